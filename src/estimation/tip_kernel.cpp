#include "artcal/estimation/tip_kernel.hpp"

#include <cstdlib>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ARTCAL_TIP_KERNEL_AVX2 1
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace artcal {

namespace {

constexpr int kRows = kTipPanelRows;

// One panel: rows of P L accumulated column by column of L, their squares summed per row.
void panelGeneric(const double* P, int n, const double* L, bool lower, double* squares) {
  double acc[kRows];
  for (int i = 0; i < kRows; ++i) squares[i] = 0.0;
  for (int c = 0; c < n; ++c) {
    for (int i = 0; i < kRows; ++i) acc[i] = 0.0;
    for (int a = lower ? c : 0; a < n; ++a) {
      const double l = L[a + static_cast<long>(c) * n];
      const double* column = P + static_cast<long>(a) * kRows;
      for (int i = 0; i < kRows; ++i) acc[i] += l * column[i];
    }
    for (int i = 0; i < kRows; ++i) squares[i] += acc[i] * acc[i];
  }
}

#ifdef ARTCAL_TIP_KERNEL_AVX2
// The same with fused multiply-adds, two columns of L at a time over half a panel (24 rows): 12
// accumulators in AVX registers, each row loaded once for both columns. For a lower-triangular L
// the pair (c, c+1) starts at row c of L, where L(c, c+1) is 0.
__attribute__((target("avx2,fma"))) void panelAvx2(const double* P, int n, const double* L,
                                                   bool lower, double* squares) {
  static_assert(kRows == 48, "two halves of 6 registers of 4");
  for (int half = 0; half < 2; ++half) {
    const double* rows = P + 24 * half;
    __m256d sq[6];
    for (auto& s : sq) s = _mm256_setzero_pd();
    int c = 0;
    for (; c + 1 < n; c += 2) {
      __m256d a0[6], a1[6];
      for (int k = 0; k < 6; ++k) a0[k] = a1[k] = _mm256_setzero_pd();
      const double* l0 = L + static_cast<long>(c) * n;
      const double* l1 = l0 + n;
      for (int a = lower ? c : 0; a < n; ++a) {
        const __m256d b0 = _mm256_broadcast_sd(l0 + a), b1 = _mm256_broadcast_sd(l1 + a);
        const double* column = rows + static_cast<long>(a) * kRows;
        for (int k = 0; k < 6; ++k) {
          const __m256d x = _mm256_loadu_pd(column + 4 * k);
          a0[k] = _mm256_fmadd_pd(b0, x, a0[k]);
          a1[k] = _mm256_fmadd_pd(b1, x, a1[k]);
        }
      }
      for (int k = 0; k < 6; ++k) {
        sq[k] = _mm256_fmadd_pd(a0[k], a0[k], sq[k]);
        sq[k] = _mm256_fmadd_pd(a1[k], a1[k], sq[k]);
      }
    }
    if (c < n) {  // the last column of an odd n
      __m256d a0[6];
      for (auto& v : a0) v = _mm256_setzero_pd();
      const double* l0 = L + static_cast<long>(c) * n;
      for (int a = lower ? c : 0; a < n; ++a) {
        const __m256d b0 = _mm256_broadcast_sd(l0 + a);
        const double* column = rows + static_cast<long>(a) * kRows;
        for (int k = 0; k < 6; ++k)
          a0[k] = _mm256_fmadd_pd(b0, _mm256_loadu_pd(column + 4 * k), a0[k]);
      }
      for (int k = 0; k < 6; ++k) sq[k] = _mm256_fmadd_pd(a0[k], a0[k], sq[k]);
    }
    for (int k = 0; k < 6; ++k) _mm256_storeu_pd(squares + 24 * half + 4 * k, sq[k]);
  }
}

// CPUID at the first evaluation, not __builtin_cpu_supports: that links libgcc's constructor,
// which runs CPUID on every start of every artcal process (a trap to the hypervisor on a virtual
// machine: a tenth of `artcal --version`). AVX2 and FMA, and the OS saving the YMM registers
// (OSXSAVE, then XCR0 bits 1 and 2).
bool processorHasAvx2Fma() {
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (!__get_cpuid(1, &eax, &ebx, &ecx, &edx)) return false;
  constexpr unsigned kFma = 1u << 12, kOsXsave = 1u << 27, kAvx = 1u << 28;
  if ((ecx & (kFma | kOsXsave | kAvx)) != (kFma | kOsXsave | kAvx)) return false;
  unsigned xcr0_low = 0, xcr0_high = 0;
  __asm__("xgetbv" : "=a"(xcr0_low), "=d"(xcr0_high) : "c"(0));
  if ((xcr0_low & 0x6u) != 0x6u) return false;
  if (!__get_cpuid_count(7, 0, &eax, &ebx, &ecx, &edx)) return false;
  constexpr unsigned kAvx2 = 1u << 5;
  return (ebx & kAvx2) != 0;
}
#endif

TipKernel chooseKernel() {
  if (const char* forced = std::getenv("ARTCAL_TIP_KERNEL");
      forced && std::strcmp(forced, "generic") == 0) {
    return TipKernel::Generic;
  }
#ifdef ARTCAL_TIP_KERNEL_AVX2
  if (processorHasAvx2Fma()) return TipKernel::Avx2Fma;
#endif
  return TipKernel::Generic;
}

}  // namespace

bool tipKernelAvailable(TipKernel kernel) {
  if (kernel == TipKernel::Generic) return true;
#ifdef ARTCAL_TIP_KERNEL_AVX2
  static const bool avx2_fma = processorHasAvx2Fma();
  return avx2_fma;
#else
  return false;
#endif
}

TipKernel activeTipKernel() {
  static const TipKernel kernel = chooseKernel();
  return kernel;
}

std::string_view tipKernelName(TipKernel kernel) {
  return kernel == TipKernel::Avx2Fma ? "avx2-fma" : "generic";
}

void tipKernelRowSquares(TipKernel kernel, const double* panels, int panel_count, int n,
                         const double* L, bool lower, double* row_squares) {
  const long panel_size = static_cast<long>(n) * kRows;
  for (int p = 0; p < panel_count; ++p) {
    const double* P = panels + p * panel_size;
    double* squares = row_squares + static_cast<long>(p) * kRows;
#ifdef ARTCAL_TIP_KERNEL_AVX2
    if (kernel == TipKernel::Avx2Fma) {
      panelAvx2(P, n, L, lower, squares);
      continue;
    }
#endif
    panelGeneric(P, n, L, lower, squares);
  }
}

void tipKernelRowSquares(const double* panels, int panel_count, int n, const double* L, bool lower,
                         double* row_squares) {
  tipKernelRowSquares(activeTipKernel(), panels, panel_count, n, L, lower, row_squares);
}

}  // namespace artcal
