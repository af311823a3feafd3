// The ITM's per-height kernel (itm_kernel.h) compiled for AVX2: this file alone is built with
// -mavx2, and itm.cpp calls its entry points (itm_kernel::avx2) only where the processor has
// AVX2.
#define TERRAVOL_ITM_KERNEL avx2
#include "volume/itm_kernel.h"
