// The JSON edit scripts `ldc edit` reads: a list of brush edits, in order.
//
//   {"edits": [
//     {"op": "subtract", "brush": "sphere", "centre": [x, y, z], "radius": r},
//     {"op": "union", "brush": "box", "centre": [..], "half_extents": [..], "material": 2,
//      "rotate_deg": 30, "axis": [0, 0, 1]},
//     {"op": "paint", "brush": "capsule", "a": [..], "b": [..], "radius": r, "material": 3},
//     {"op": "intersect", "brush": "cylinder", "a": [..], "b": [..], "radius": r},
//     {"op": "subtract", "brush": "noise", "centre": [..], "radius": r,
//      "amplitude": 0.25, "frequency": 2, "seed": 1},
//     {"op": "union", "brush": "mesh", "mesh": "rock.obj", "translate": [..], "scale": 1.0,
//      "rotate_deg": 0, "axis": [0, 0, 1], "material": 1}
//   ]}
//
// Unknown fields are refused (they are usually typos), as are missing or
// wrong-typed fields and non-finite numbers; every message names the edit's
// index and the field. The brushes are checked with check_brush while the
// script is read, so a bad script fails before the world is touched.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "csg/csg.h"
#include "ldc/status.h"

namespace ldc::tool {

// The script format, for the command's help text.
extern const char* const kEditScriptHelp;

struct ScriptEdit {
  std::string brush_name;  // as written in the script ("sphere", "noise", ...), for the report
  WorldEditor::Edit edit;
};

// Reads and checks a script; mesh brushes' files are loaded (relative paths
// are taken from the script's folder).
Result<std::vector<ScriptEdit>> read_edit_script(const std::string& path);

// Loads a mesh brush's file, its path already resolved against the script's folder.
using MeshLoader = std::function<Result<TriangleMesh>(const std::string& path)>;
// The same from the script's text: `path` names it in messages and gives the
// folder of relative mesh files; `load` reads them (tests and the fuzzer pass
// one that touches no file).
Result<std::vector<ScriptEdit>> read_edit_script_text(std::string_view text, const std::string& path,
                                                      const MeshLoader& load);

}  // namespace ldc::tool
