// Rasterizers for the brush shapes, onto a given lattice and chunk grid.
#pragma once

#include "csg/csg.h"

namespace ldc::detail {

// A GridConfig that reproduces `lattice` and its chunk grid exactly, with
// one cell of padding around the input.
GridConfig aligned_grid(const Lattice& lattice, int chunk_size);

Result<World> rasterize_primitive(const Primitive& primitive, const Lattice& lattice, int chunk_size, Context* ctx = nullptr);
Result<World> rasterize_noise_sphere(const NoiseShape& shape, uint16_t material, const Lattice& lattice, int chunk_size,
                                    Context* ctx = nullptr);
Result<World> rasterize_mesh_brush(const MeshShape& shape, uint16_t material, const Lattice& lattice, int chunk_size,
                                  Context* ctx = nullptr);

// The noise sphere as an implicit solid (for tests and the rasterizer).
std::unique_ptr<ImplicitSolid> make_noise_sphere_solid(const NoiseShape& shape, uint16_t material = 0);

}  // namespace ldc::detail
