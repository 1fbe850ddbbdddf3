// The only translation unit that includes OpenVDB.
#include "voxelize/vdb.h"

#include <exception>
#include <fstream>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "ldc/io.h"

namespace ldc {
namespace {

openvdb::math::Transform::Ptr voxel_transform(const VoxelGrid& g) {
  openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(g.voxel_size);
  const glm::dvec3 c = g.origin + 0.5 * g.voxel_size;
  t->postTranslate(openvdb::Vec3d(c.x, c.y, c.z));
  return t;
}

void add_meta(openvdb::GridBase& grid, const VoxelGrid& g, const std::string& source) {
  grid.insertMeta("voxel_size", openvdb::DoubleMetadata(g.voxel_size));
  if (!source.empty()) grid.insertMeta("ldc_source", openvdb::StringMetadata(source));
}

openvdb::FloatGrid::Ptr occupancy_grid(const VoxelGrid& g) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  if (!g.box.empty()) {
    const openvdb::CoordBBox bbox(openvdb::Coord(g.box.lo.x, g.box.lo.y, g.box.lo.z),
                                  openvdb::Coord(g.box.hi().x - 1, g.box.hi().y - 1, g.box.hi().z - 1));
    // LayoutXYZ: x changes fastest, as in VoxelGrid::occupancy.
    openvdb::tools::Dense<const float, openvdb::tools::LayoutXYZ> dense(bbox, g.occupancy.data());
    openvdb::tools::copyFromDense(dense, *grid, 0.0f);
  }
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

// The surface voxels' weighted mean normal and albedo over their faces.
void surface_grids(const VoxelGrid& g, openvdb::Vec3SGrid& normal, openvdb::Vec3SGrid& albedo) {
  auto n_acc = normal.getAccessor();
  auto a_acc = albedo.getAccessor();
  for (size_t i = 0; i < g.surface.size(); ++i) {
    glm::vec3 n(0.0f), a(0.0f);
    float w = 0.0f;
    for (const FaceSample& f : g.surface_faces[i]) {
      if (f.flags != kFaceOwn) continue;
      n += f.albedo.a * f.normal;
      a += f.albedo.a * glm::vec3(f.albedo);
      w += f.albedo.a;
    }
    if (!(w > 0.0f)) continue;
    const float len = glm::length(n);
    if (len > 0.0f) n /= len;
    a /= w;
    const openvdb::Coord c(g.surface[i].x, g.surface[i].y, g.surface[i].z);
    n_acc.setValue(c, openvdb::Vec3s(n.x, n.y, n.z));
    a_acc.setValue(c, openvdb::Vec3s(a.x, a.y, a.z));
  }
}

void add_grids(const VdbGridSet& set, const std::string& source, openvdb::GridPtrVec* out) {
  const VoxelGrid& g = *set.grid;
  openvdb::math::Transform::Ptr xform = voxel_transform(g);
  openvdb::FloatGrid::Ptr occ = occupancy_grid(g);
  occ->setName("occupancy" + set.suffix);
  occ->setTransform(xform);
  add_meta(*occ, g, source);
  out->push_back(occ);
  if (!g.has_faces) return;
  openvdb::Vec3SGrid::Ptr normal = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  openvdb::Vec3SGrid::Ptr albedo = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  surface_grids(g, *normal, *albedo);
  normal->setName("normal" + set.suffix);
  normal->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
  albedo->setName("albedo" + set.suffix);
  for (openvdb::GridBase::Ptr grid : {openvdb::GridBase::Ptr(normal), openvdb::GridBase::Ptr(albedo)}) {
    grid->setTransform(xform);
    add_meta(*grid, g, source);
    out->push_back(grid);
  }
}

}  // namespace

Status save_vdb(const std::vector<VdbGridSet>& grids, const std::string& path, const std::string& source) {
  // OpenVDB opens the file by name: it writes AtomicFile's temp file, which
  // is renamed over `path` only once whole (ldc/io.h).
  Result<AtomicFile> target = AtomicFile::create(path);
  if (!target.ok()) {
    std::string why = target.status().message();
    if (why.rfind(path + ": ", 0) == 0) why.erase(0, path.size() + 2);
    return {ErrorCode::kIoError, path + ": cannot write the .vdb file: " + why};
  }
  target.value().close_stream();
  try {
    openvdb::initialize();
    openvdb::GridPtrVec out;
    for (const VdbGridSet& set : grids) add_grids(set, source, &out);
    // io::File::write never checks its stream after writing, so a full
    // disk gave a truncated file and success; io::Stream writes the same
    // grids (without the offsets table for random access, which readers
    // do not need) to a stream whose state is checked here.
    std::ofstream os(target.value().temp_path(), std::ios::binary | std::ios::trunc);
    openvdb::io::Stream(os).write(out);
    os.close();
    if (!os) return {ErrorCode::kIoError, path + ": cannot write the .vdb file: write failed (disk full?)"};
  } catch (const std::exception& e) {
    return {ErrorCode::kIoError, path + ": cannot write the .vdb file: " + e.what()};
  }
  return target.value().commit();
}

Status save_vdb(const VoxelGrid& grid, const std::string& path, const std::string& source) {
  return save_vdb(std::vector<VdbGridSet>{{&grid, ""}}, path, source);
}

Status save_vdb(const Cascades& cascades, const std::string& path, const std::string& source) {
  const std::vector<NamedLevelGrid> levels = valid_level_grids(cascades);
  std::vector<VdbGridSet> sets;
  for (const NamedLevelGrid& l : levels) sets.push_back({&l.grid, l.suffix});
  return save_vdb(sets, path, source);
}

}  // namespace ldc
