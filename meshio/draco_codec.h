// The seam between meshio and its Draco codec: meshio calls these two
// functions for .drc files, and exactly one definition is linked in. The
// library ldc::meshio defines them in draco.cpp (linking libdraco); the ldc
// tool links meshio without draco.cpp (ldc_meshio_no_draco) and defines them
// in tools/draco_codec.cpp through its dlopen()ed Draco plugin (issue 22).
// Not installed: meshio's and the tool's own.
#pragma once

#include <string>
#include <string_view>

#include "meshio/meshio.h"

namespace ldc::meshio_detail {

// "path: message" with the given code.
Status error_at(ErrorCode code, std::string_view path, std::string_view message);

Result<std::string> encode_draco(const ContourMesh& mesh, const ExportOptions& options,
                                 const std::string& path);
Result<ContourMesh> decode_draco(std::string_view bytes, const std::string& path);

}  // namespace ldc::meshio_detail
