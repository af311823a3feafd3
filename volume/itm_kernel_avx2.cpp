// The ITM's per-height kernel (itm_kernel.h) compiled for AVX2 (this file alone is built with
// -mavx2; itm.cpp calls it only where the processor has AVX2).
#define TERRAVOL_ITM_KERNEL avx2
#include "volume/itm_kernel.h"

namespace terravol::volume::itm_kernel::avx2 {

void evaluate(const Path& p, Lanes& lanes) { evaluate_lanes(p, lanes); }

}  // namespace terravol::volume::itm_kernel::avx2
