// The sheets of surface through one lattice cell, from the signs of its eight
// corners alone: what makes the contoured mesh a 2-manifold.
//
// Each face of the cell pairs the crossings on its edges into segments: a
// face with two crossings joins them; a face with four (two inside corners on
// one diagonal) joins the crossings around each inside corner, so the two
// inside corners are kept apart. The rule reads only the face's corners, so
// both cells sharing a face pair its crossings the same way (one exception,
// decided from both cells' corners: face_links_both_segments). Every crossing
// lies on two faces of the cell, so the segments close into loops; each loop
// bounds one disk of surface in the cell: a sheet. Dual contouring places one
// vertex per sheet (not per cell), and the quad of a crossing edge joins, in
// each of its four cells, the sheet that holds that edge. Then every vertex's
// triangles form one disk, and two cells sharing a face are joined by one
// mesh edge per face segment.
//
// Corners are numbered by bits (x, y, z); a cell's 12 edges by slot
// axis * 4 + k, where k = (offset along axis_u(axis)) + 2 * (offset along
// axis_v(axis)) of the edge's lower corner.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace ldc::detail {

struct CellSheets {
  static constexpr int kMaxSheets = 4;
  uint8_t count = 0;         // sheets through the cell (0 when all corners agree)
  int8_t sheet_of_edge[12];  // the sheet holding each edge's crossing; -1 when its ends agree
  // The edge slots around each sheet's loop, in order: counter-clockwise seen
  // from the outside of the solid (so a fan over them faces outwards).
  uint8_t loop_size[kMaxSheets];
  uint8_t loop[kMaxSheets][12];
};

// The table entry for a cell whose inside corners are the set bits, with the
// faces whose bits are set in `joined_faces` (face 2 * axis + side: x = 0,
// x = 1, y = 0, y = 1, z = 0, z = 1) joining their two diagonal inside
// corners instead of keeping them apart (ignored on faces that are not
// ambiguous).
const CellSheets& cell_sheets(unsigned inside_corners, unsigned joined_faces = 0);

// Whether the face holds two diagonal inside corners and two outside ones.
bool face_is_ambiguous(unsigned inside_corners, int face);

// Whether, under the default rule, one sheet of the cell passes through both
// segments of an ambiguous face. When the cells on both sides of a face do,
// their two vertices would be joined by two quads' edges (a tunnel thinner
// than a cell): that face is joined instead, from both sides, which turns the
// tunnel into two sheets on one side or the other.
bool face_links_both_segments(unsigned inside_corners, int face);

// The faces of `cell` (inside corners `corners`) to join: those whose cells
// on both sides would link both of the face's segments. corners_of(c)
// gives the inside corners of a neighbouring cell c, or -1 when it is not
// known (that face stays apart). The meshers' one rule, so that dual
// contouring and marching cubes split and join the same faces.
template <class CornersOf>
unsigned joined_faces(const glm::ivec3& cell, unsigned corners, CornersOf&& corners_of) {
  unsigned joined = 0;
  for (int face = 0; face < 6; ++face) {
    if (!face_links_both_segments(corners, face)) continue;  // false on faces that are not ambiguous
    const int axis = face / 2, side = face % 2;
    glm::ivec3 across = cell;
    across[axis] += side ? 1 : -1;
    const int across_corners = corners_of(across);
    if (across_corners >= 0 && face_links_both_segments(unsigned(across_corners), 2 * axis + 1 - side))
      joined |= 1u << face;
  }
  return joined;
}

// The lower corner's offset in the cell, and the axis, of edge slot `slot`.
glm::ivec3 cell_edge_offset(int slot);
inline int cell_edge_axis(int slot) { return slot / 4; }

// The slot of the edge along `axis` whose lower corner is at `offset` (each 0 or 1).
inline int cell_edge_slot(int axis, const glm::ivec3& offset) {
  return axis * 4 + offset[(axis + 1) % 3] + 2 * offset[(axis + 2) % 3];
}

}  // namespace ldc::detail
