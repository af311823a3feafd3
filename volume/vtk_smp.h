// Switching VTK's SMP tools to their sequential backend (in the forked reader child, where TBB
// must not run). Private to volume/ and objects/. vtkSMPTools.h does not compile as C++20 (a constructor
// declared with a template-id), so vtk_smp.cpp alone is compiled as C++17.
#pragma once

namespace terravol::volume::detail {

void use_sequential_vtk_smp();

}  // namespace terravol::volume::detail
