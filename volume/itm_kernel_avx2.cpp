// The ITM's per-height kernel (itm_kernel.h) compiled for AVX2 (this file alone is built with
// -mavx2; itm.cpp calls it only where the processor has AVX2).
#define TERRAVOL_ITM_KERNEL avx2
#include "volume/itm_kernel.h"

namespace terravol::volume::itm_kernel::avx2 {

void evaluate(const Path& p, Lanes& lanes) { evaluate_lanes(p, lanes); }

Sums resample(const double* z, int np, int k0, double xa, double step, int n, double* s) {
  return resample_lanes(z, np, k0, xa, step, n, s);
}

Counts beyond(const double* s, int n, double at0, double slope, double low_threshold, double high_threshold, double* low,
              double* high) {
  return beyond_lanes(s, n, at0, slope, low_threshold, high_threshold, low, high);
}

}  // namespace terravol::volume::itm_kernel::avx2
