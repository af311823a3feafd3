#include "volume/vtk_smp.h"

#include <vtkSMPTools.h>

namespace terravol::volume::detail {

void use_sequential_vtk_smp() { vtkSMPTools::SetBackend("Sequential"); }

}  // namespace terravol::volume::detail
