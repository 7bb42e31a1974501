#pragma once
// The kernel of S_m^2 = tr(J_p V_p J_p^T) = |J_p L|_F^2 (V_p = L L^T) over a workspace
// (estimation/tip.hpp), blocked over configurations so that each block's product is made and
// consumed in the first-level cache: the tip Jacobians are kept in panels of kTipPanelRows rows
// (kTipPanelRows / dimension configurations, their rows in order), each panel column after column
// (panel[a * kTipPanelRows + i] = J_p(row i of the panel, parameter a)), and for each panel the
// rows of J L are accumulated one column of L at a time in registers, their squares summed per
// row. 5 MB of Jacobians for a 6-axis arm's 21 parameters over 10,000 configurations, against
// 15 MB of Gram matrices.
//
// Two builds of the same loop: a generic one (the build's instruction set, x86-64 SSE2 unless
// ARTCAL_NATIVE), and on x86-64 one for AVX2 with FMA, chosen at run time when the processor has
// both (__builtin_cpu_supports). The FMA rounds each multiply-add once, so the two agree to a few
// units in the last place of each sum of squares, not bit for bit (tests/estimation/
// test_tip_kernel.cpp checks 1e-13 relative); ARTCAL_TIP_KERNEL=generic in the environment
// forces the generic one.

#include <string_view>

namespace artcal {

/// Rows of J_p per panel: 16 configurations of a 3-D tip, 24 of a planar one, 8 of a pose.
inline constexpr int kTipPanelRows = 48;

enum class TipKernel { Generic, Avx2Fma };

/// Whether this processor runs `kernel` (Generic always).
bool tipKernelAvailable(TipKernel kernel);
/// The kernel tipKernelRowSquares uses on this processor (and environment).
TipKernel activeTipKernel();
std::string_view tipKernelName(TipKernel kernel);

/// For `panels` panels of `n` columns each: row_squares[p * kTipPanelRows + i] = |row i of
/// (panel p) L|^2, L an n x n column-major matrix, lower-triangular when `lower` (its upper
/// triangle then zero). A kernel the processor lacks runs as Generic.
void tipKernelRowSquares(TipKernel kernel, const double* panels, int panel_count, int n,
                         const double* L, bool lower, double* row_squares);

/// The same with activeTipKernel().
void tipKernelRowSquares(const double* panels, int panel_count, int n, const double* L, bool lower,
                         double* row_squares);

}  // namespace artcal
