#pragma once
// One reading's rows of an observation block (design_matrix.hpp), transformed in place by small
// kernels: the builder's whitening and the calibrator's re-whitening share the walk over the
// block's parts and the choice of a kernel whose row count is known at compile time.

#include <Eigen/Core>

#include "artcal/estimation/design_matrix.hpp"

namespace artcal {

/// f.template operator()<K>() with K = n for a reading of 1, 2 or 3 rows (a point: loops of
/// known length), Eigen::Dynamic for more (a pose's 6).
template <typename F>
void withReadingRows(int n, F&& f) {
  switch (n) {
    case 1:
      return f.template operator()<1>();
    case 2:
      return f.template operator()<2>();
    case 3:
      return f.template operator()<3>();
    default:
      return f.template operator()<Eigen::Dynamic>();
  }
}

/// op(first, stride, cols) on the rows from `row` of each part of `block` that has columns (A_p,
/// A_r, A_c: one without, no systematic error, may have no data to point into) and, when
/// `with_residuals`, of e: column-major, each column's rows contiguous from `first`.
template <typename Op>
void forEachPartAtRow(ObservationBlock& block, int row, bool with_residuals, Op&& op) {
  for (Eigen::MatrixXd* part : {&block.A_p, &block.A_r, &block.A_c}) {
    if (part->cols() > 0) op(part->data() + row, part->outerStride(), part->cols());
  }
  if (with_residuals) op(block.e.data() + row, block.e.size(), Eigen::Index{1});
}

}  // namespace artcal
