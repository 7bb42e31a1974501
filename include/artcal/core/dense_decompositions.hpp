#pragma once
// Eigen's dense decompositions of Eigen::MatrixXd, instantiated once for the whole project.
//
// Include this header instead of <Eigen/Cholesky>, <Eigen/LU>, <Eigen/QR>, <Eigen/SVD> or
// <Eigen/Eigenvalues> where a file decomposes an Eigen::MatrixXd. The explicit instantiation
// declarations below (`extern template`) keep the compiler from instantiating, optimising and
// emitting the decompositions' out-of-line work (JacobiSVD::compute, LDLT::compute<MatrixXd>,
// ColPivHouseholderQR::computeInPlace...) in every translation unit that uses one: that work is
// compiled once, in src/core/dense_decompositions.cpp, and linked from artcal_core. Eigen's inline
// members (solve, the accessors) are still instantiated where they are used, as they must be.
// The tests see this header through their precompiled header (tests/CMakeLists.txt).
//
// What is covered: the classes below for Eigen::MatrixXd, and for LLT, LDLT and
// SelfAdjointEigenSolver the decomposition of an Eigen::MatrixXd (a named matrix or .ldlt() /
// .llt() of one); a decomposition of an expression (a block, a product) is instantiated where it
// is written, as before. Fixed-size decompositions (Matrix3d...) are small and left alone.
// Internal: not included by the public headers, not installed.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

extern template class Eigen::JacobiSVD<Eigen::MatrixXd>;
extern template class Eigen::ColPivHouseholderQR<Eigen::MatrixXd>;
extern template class Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>;
extern template class Eigen::PartialPivLU<Eigen::MatrixXd>;
extern template class Eigen::FullPivLU<Eigen::MatrixXd>;
extern template Eigen::LLT<Eigen::MatrixXd>& Eigen::LLT<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(
    const Eigen::EigenBase<Eigen::MatrixXd>&);
extern template Eigen::LDLT<Eigen::MatrixXd>& Eigen::LDLT<Eigen::MatrixXd>::compute<
    Eigen::MatrixXd>(const Eigen::EigenBase<Eigen::MatrixXd>&);
extern template Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>&
Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(
    const Eigen::EigenBase<Eigen::MatrixXd>&, int);
