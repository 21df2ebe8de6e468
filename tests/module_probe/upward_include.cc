// Compiled as part of the util module (which links nothing above it), this file includes a header
// of geometry, the module above: the build must refuse it. The test ModuleGraph.UpwardIncludeFails
// builds it and expects the compiler to report the header as not found.
#include "finecap/geometry/mesh.h"
#include "finecap/util/error.h"

int UpwardIncludeProbe() { return 0; }
