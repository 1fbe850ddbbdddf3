// The 256-entry sheet table, traced once from the face rule (see
// detail/cell_sheets.h) rather than typed in: the rule is the specification.
#include "contour/detail/cell_sheets.h"

#include <array>
#include <vector>

namespace ldc::detail {
namespace {

// The six faces as corner loops, counter-clockwise seen from outside the cube.
constexpr int kFaces[6][4] = {
    {0, 4, 6, 2},  // x = 0
    {1, 3, 7, 5},  // x = 1
    {0, 1, 5, 4},  // y = 0
    {2, 6, 7, 3},  // y = 1
    {0, 2, 3, 1},  // z = 0
    {4, 5, 7, 6},  // z = 1
};

glm::ivec3 corner(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

// The slot of the cube edge between two corners that differ in one coordinate.
int slot_between(int a, int b) {
  glm::ivec3 pa = corner(a), pb = corner(b);
  int axis = 0;
  for (int i = 0; i < 3; ++i)
    if (pa[i] != pb[i]) axis = i;
  return cell_edge_slot(axis, glm::min(pa, pb));
}

// next[s] = the crossing after crossing s on its loop. Walking each face
// counter-clockwise seen from outside the cube, a run of inside corners
// gives one segment, from the crossing entering the run to the one leaving it.
// On a joined face (a bit of `joined_faces`, two diagonal inside corners) the
// inside corners are joined instead: each segment runs from the crossing
// entering an inside corner back round the outside corner before it.
std::array<int, 12> trace_segments(unsigned inside, unsigned joined_faces) {
  std::array<int, 12> next;
  next.fill(-1);
  auto in = [&](int c) { return ((inside >> c) & 1) != 0; };
  for (int face = 0; face < 6; ++face) {
    const int* f = kFaces[face];
    const bool join = ((joined_faces >> face) & 1) && in(f[0]) == in(f[2]) && in(f[1]) == in(f[3]) && in(f[0]) != in(f[1]);
    for (int k = 0; k < 4; ++k) {
      int a = f[k], b = f[(k + 1) % 4];
      if (in(a) || !in(b)) continue;
      if (join) {
        next[slot_between(a, b)] = slot_between(f[(k + 3) % 4], a);
        continue;
      }
      int j = (k + 1) % 4;
      while (in(f[(j + 1) % 4])) j = (j + 1) % 4;
      next[slot_between(a, b)] = slot_between(f[j], f[(j + 1) % 4]);
    }
  }
  return next;
}

CellSheets make_entry(unsigned inside, unsigned joined_faces) {
  CellSheets s;
  for (int8_t& e : s.sheet_of_edge) e = -1;
  for (uint8_t& n : s.loop_size) n = 0;
  std::array<int, 12> next = trace_segments(inside, joined_faces);
  for (int start = 0; start < 12; ++start) {
    if (next[start] < 0 || s.sheet_of_edge[start] >= 0) continue;
    const int sheet = s.count++;
    for (int e = start; s.sheet_of_edge[e] < 0; e = next[e]) {
      s.sheet_of_edge[e] = int8_t(sheet);
      s.loop[sheet][s.loop_size[sheet]++] = uint8_t(e);
    }
  }
  return s;
}

std::vector<CellSheets> make_table() {
  std::vector<CellSheets> table(256 * 64);
  for (unsigned joined = 0; joined < 64; ++joined)
    for (unsigned c = 0; c < 256; ++c) table[joined * 256 + c] = make_entry(c, joined);
  return table;
}

}  // namespace

const CellSheets& cell_sheets(unsigned inside_corners, unsigned joined_faces) {
  static const std::vector<CellSheets> table = make_table();  // 16,384 entries, about 1 MB, traced in a few ms
  return table[(joined_faces & 63u) * 256 + (inside_corners & 255u)];
}

bool face_is_ambiguous(unsigned inside_corners, int face) {
  const int* f = kFaces[face];
  auto in = [&](int c) { return ((inside_corners >> c) & 1) != 0; };
  return in(f[0]) == in(f[2]) && in(f[1]) == in(f[3]) && in(f[0]) != in(f[1]);
}

bool face_links_both_segments(unsigned inside_corners, int face) {
  if (!face_is_ambiguous(inside_corners, face)) return false;
  const CellSheets& s = cell_sheets(inside_corners);
  const int* f = kFaces[face];
  const int first = s.sheet_of_edge[slot_between(f[0], f[1])];
  for (int k = 1; k < 4; ++k) {
    if (s.sheet_of_edge[slot_between(f[k], f[(k + 1) % 4])] != first) return false;
  }
  return true;
}

glm::ivec3 cell_edge_offset(int slot) {
  const int axis = slot / 4, k = slot % 4;
  glm::ivec3 o(0);
  o[(axis + 1) % 3] = k & 1;
  o[(axis + 2) % 3] = k >> 1;
  return o;
}

}  // namespace ldc::detail
