// Deprecated: mesh files moved to the meshio module (meshio/meshio.h, target
// ldc::meshio) in 0.3. This header forwards there for one version; include
// "meshio/meshio.h" and link ldc::meshio instead.
#pragma once

#include "meshio/meshio.h"
