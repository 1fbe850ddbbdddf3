// Exact integer predicates on fixed-point coordinates, with simulation of
// simplicity (Edelsbrunner & Muecke 1990) for ties.
//
// Coordinates are lattice coordinates times 2^kFixedBits, at most 2^37 in
// magnitude (kMaxNodeCoordinate = 2^20 nodes), so 2D orientations fit in 2^76
// and 3D plane values in 2^114: both exact in 128-bit integers.
//
// The symbolic perturbation moves every lattice point by (dx, dy, dz) with
// dx >> dy >> dz > 0 (infinitesimals). A ray of axis a through a lattice line
// is perturbed with it, so it never passes exactly through a mesh edge or
// vertex, and a node never lies exactly on a triangle's plane. Because one
// perturbation serves all three axes, the three rays through a node count the
// same winding number for it.
#pragma once

#include <cstdint>

namespace ldc::detail {

__extension__ typedef __int128 i128;

inline constexpr int kFixedBits = 16;
inline constexpr int64_t kFixedOne = int64_t{1} << kFixedBits;

template <class T>
constexpr int sign_of(T v) {
  return (v > 0) - (v < 0);
}

// Does the perturbation of the first (u) ray coordinate dominate the second (v)?
// X rays (u, v) = (y, z): dy >> dz, yes. Y rays (z, x): dx >> dz, no. Z rays (x, y): yes.
constexpr bool u_perturbation_dominates(int axis) { return axis != 1; }

// Sign that the perturbation gives the edge function of edge P->Q (direction
// (du, dv) = Q - P) at a point lying exactly on its line. Never 0 for du, dv
// not both 0. The edge function E(R) = du*(R.v-P.v) - dv*(R.u-P.u) moves by
// du*dv_perturb - dv*du_perturb.
constexpr int edge_tie_sign(int64_t du, int64_t dv, bool u_dominates) {
  if (u_dominates) return dv != 0 ? -sign_of(dv) : sign_of(du);
  return du != 0 ? sign_of(du) : -sign_of(dv);
}

// Sign of the plane value n . (node + perturbation - A) given its exact value
// `plane` at the unperturbed node and the normal n = (nx, ny, nz).
constexpr int perturbed_plane_sign(i128 plane, i128 nx, i128 ny, i128 nz) {
  if (plane != 0) return sign_of(plane);
  if (nx != 0) return sign_of(nx);
  if (ny != 0) return sign_of(ny);
  return sign_of(nz);
}

}  // namespace ldc::detail
