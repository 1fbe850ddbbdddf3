// Writes the soup test levels of tests/data/levels (issue 20): game levels as
// artists make them, in RecastDemo's style. Triangle soups, not solids:
// one-sided floor planes, rooms open on a side, single-quad walls, floating
// props, closed boxes overlapping each other, T-junctions, a floor wound the
// wrong way and a duplicated quad. Wavefront OBJ, y up, metres, one `o` name
// per part and a `g` group per kind of part.
//
//   make_levels OUTDIR    writes OUTDIR/soup_rooms.obj, soup_storeys.obj, soup_yard.obj
//
// Deterministic: no random numbers, coordinates printed with 4 decimals, so
// the committed files are reproduced byte for byte (ctest
// levels.generator_reproduces_committed_files).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace {

using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;
const dvec3 kUp{0, 1, 0}, kDown{0, -1, 0};
const dvec3 kPosX{1, 0, 0}, kNegX{-1, 0, 0}, kPosZ{0, 0, 1}, kNegZ{0, 0, -1};

std::string number(double x) {
  if (std::abs(x) < 5e-5) x = 0.0;  // no "-0.0000"
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", x);
  return buf;
}

// An OBJ being written: parts, their vertices and faces (1-based indices).
class Obj {
 public:
  explicit Obj(const std::string& header) { text_ = header; }

  void part(const std::string& name, const std::string& group) {
    if (group != group_) {
      text_ += "g " + group + "\n";
      group_ = group;
    }
    text_ += "o " + name + "\n";
  }

  int vertex(const dvec3& p) {
    text_ += "v " + number(p.x) + " " + number(p.y) + " " + number(p.z) + "\n";
    return ++vertices_;
  }

  void face(const std::vector<int>& indices) {
    text_ += 'f';
    for (int i : indices) {
      text_ += ' ';
      text_ += std::to_string(i);
    }
    text_ += '\n';
    triangles_ += indices.size() - 2;
  }

  // A planar convex polygon, wound so that its normal (right-hand rule)
  // points along `facing`; its own vertices.
  void polygon(std::vector<dvec3> points, const dvec3& facing) {
    dvec3 normal(0.0);  // Newell's method
    for (size_t i = 0; i < points.size(); ++i) {
      const dvec3& a = points[i];
      const dvec3& b = points[(i + 1) % points.size()];
      normal += dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    if (glm::dot(normal, facing) < 0.0) std::reverse(points.begin(), points.end());
    std::vector<int> indices;
    for (const dvec3& p : points) indices.push_back(vertex(p));
    face(indices);
  }

  void quad(const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& d, const dvec3& facing) {
    polygon({a, b, c, d}, facing);
  }

  // A horizontal quad [x0, x1] x [z0, z1] at height y.
  void flat(double x0, double z0, double x1, double z1, double y, const dvec3& facing) {
    quad({x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}, facing);
  }

  // A closed axis-aligned box, faces outward, 8 shared vertices.
  void box(const dvec3& lo, const dvec3& hi) {
    int v[8];
    for (int i = 0; i < 8; ++i) v[i] = vertex({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    // Each face counter-clockwise seen from outside.
    face({v[0], v[4], v[6], v[2]});  // -x
    face({v[1], v[3], v[7], v[5]});  // +x
    face({v[0], v[1], v[5], v[4]});  // -y
    face({v[2], v[6], v[7], v[3]});  // +y
    face({v[0], v[2], v[3], v[1]});  // -z
    face({v[4], v[5], v[7], v[6]});  // +z
  }

  size_t triangles() const { return triangles_; }

  bool write(const std::string& path) const {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    const bool ok = std::fwrite(text_.data(), 1, text_.size(), f) == text_.size();
    return std::fclose(f) == 0 && ok;
  }

 private:
  std::string text_, group_;
  int vertices_ = 0;
  size_t triangles_ = 0;
};

// A gap in a wall: [u0, u1] along it from its start, [y0, y1] in height.
struct Opening {
  double u0, u1, y0, y1;
};

// A vertical wall of zero thickness from `a` to `b` (x and z; their y is
// ignored), from height y0 to y1, made of single quads around the openings
// (which must not overlap), each quad its own vertices: T-junctions where the
// strips meet, as modellers leave them.
void wall(Obj& obj, dvec3 a, dvec3 b, double y0, double y1, std::vector<Opening> openings, const dvec3& facing) {
  a.y = b.y = 0.0;
  const double length = glm::length(b - a);
  const dvec3 dir = (b - a) / length;
  auto at = [&](double u, double y) { return a + dir * u + dvec3(0, y, 0); };
  auto strip = [&](double u0, double u1, double v0, double v1) {
    if (u1 - u0 > 1e-9 && v1 - v0 > 1e-9) obj.quad(at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1), facing);
  };
  std::sort(openings.begin(), openings.end(), [](const Opening& p, const Opening& q) { return p.u0 < q.u0; });
  double u = 0.0;
  for (const Opening& o : openings) {
    strip(u, o.u0, y0, y1);
    strip(o.u0, o.u1, y0, std::max(y0, o.y0));  // below a window
    strip(o.u0, o.u1, std::min(y1, o.y1), y1);  // lintel
    u = o.u1;
  }
  strip(u, length, y0, y1);
}

// --- soup_rooms.obj -----------------------------------------------------------

Obj soup_rooms() {
  Obj obj(
      "# soup_rooms.obj: rooms, props, stairs, a ramp and a bridge as a triangle soup (50 x 40 m).\n"
      "# Generated by tests/levels/make_levels.cpp; do not edit. y up, metres.\n");

  // Ground: three pieces that share no vertices; the west piece is a 5 m grid,
  // so its vertices along x = 25 sit on the edges of the east pieces
  // (T-junctions), and the north-east piece's middle vertex on the south-east
  // piece's edge.
  obj.part("ground_west", "ground");
  {
    std::vector<std::vector<int>> v(6, std::vector<int>(9));
    for (int i = 0; i <= 5; ++i)
      for (int j = 0; j <= 8; ++j) v[i][j] = obj.vertex({5.0 * i, 0.0, 5.0 * j});
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 8; ++j) obj.face({v[i][j], v[i][j + 1], v[i + 1][j + 1], v[i + 1][j]});
  }
  obj.part("ground_east_south", "ground");
  obj.flat(25, 0, 50, 20, 0.0, kUp);
  obj.part("ground_east_north", "ground");
  {
    const int a = obj.vertex({25, 0, 20}), b = obj.vertex({37.5, 0, 20}), c = obj.vertex({50, 0, 20});
    const int d = obj.vertex({25, 0, 40}), e = obj.vertex({37.5, 0, 40}), f = obj.vertex({50, 0, 40});
    obj.face({a, d, e, b});
    obj.face({b, e, f, c});
  }

  // Room A: open-topped, 10 x 8 m, walls 3 m high facing in, one quad each
  // except the south wall, which has a door 2.2 m wide and 2.4 m high.
  obj.part("room_a_wall_south", "walls");
  wall(obj, {2, 0, 2}, {12, 0, 2}, 0.0, 3.0, {{4.0, 6.2, 0.0, 2.4}}, kPosZ);
  obj.part("room_a_wall_north", "walls");
  obj.quad({2, 0, 10}, {12, 0, 10}, {12, 3, 10}, {2, 3, 10}, kNegZ);
  obj.part("room_a_wall_west", "walls");
  obj.quad({2, 0, 2}, {2, 0, 10}, {2, 3, 10}, {2, 3, 2}, kPosX);
  obj.part("room_a_wall_east", "walls");
  obj.quad({12, 0, 2}, {12, 0, 10}, {12, 3, 10}, {12, 3, 2}, kNegX);
  // Props in room A: crates (one stacked, sitting on the one under it) and a
  // table on four legs (top 0.8 m: low enough to climb, too small to stand on).
  obj.part("room_a_crate_1", "props");
  obj.box({3, 0, 3}, {4, 1, 4});
  obj.part("room_a_crate_2", "props");
  obj.box({3, 0, 4.1}, {4, 1, 5.1});
  obj.part("room_a_crate_stacked", "props");
  obj.box({3.1, 1, 3.1}, {3.9, 1.8, 3.9});
  obj.part("room_a_table_top", "props");
  obj.box({8.5, 0.72, 7}, {10.5, 0.8, 8});
  const double leg = 0.08;
  for (int i = 0; i < 4; ++i) {
    const double x = i & 1 ? 10.45 - leg : 8.55, z = i & 2 ? 7.95 - leg : 7.05;
    obj.part("room_a_table_leg_" + std::to_string(i + 1), "props");
    obj.box({x, 0, z}, {x + leg, 0.72, z + leg});
  }

  // Raised platform 6 x 6 m, 3 m high: a one-sided top and four side quads
  // facing out, no bottom.
  obj.part("platform_top", "platform");
  obj.flat(18, 3, 24, 9, 3.0, kUp);
  obj.part("platform_sides", "platform");
  obj.quad({18, 0, 3}, {24, 0, 3}, {24, 3, 3}, {18, 3, 3}, kNegZ);
  obj.quad({18, 0, 9}, {24, 0, 9}, {24, 3, 9}, {18, 3, 9}, kPosZ);
  obj.quad({18, 0, 3}, {18, 0, 9}, {18, 3, 9}, {18, 3, 3}, kNegX);
  obj.quad({24, 0, 3}, {24, 0, 9}, {24, 3, 9}, {24, 3, 3}, kPosX);
  // Stairs up its west side: 12 separate closed boxes, each 0.25 m higher
  // than the one before and 0.35 m deep, overlapping the next by 0.05 m.
  for (int k = 1; k <= 12; ++k) {
    obj.part("stairs_step_" + std::to_string(k), "stairs");
    const double x0 = 18.0 - (13 - k) * 0.35;
    obj.box({x0, 0.0, 4.5}, {std::min(18.0, x0 + 0.4), 0.25 * k, 7.0});
  }
  // Bridge east from the platform: a one-sided deck 3 m over the ground
  // (12 x 2.5 m) and a railing quad 1 m high along each side.
  obj.part("bridge_deck", "bridge");
  obj.flat(24, 5, 36, 7.5, 3.0, kUp);
  obj.part("bridge_railing_south", "bridge");
  obj.quad({24, 3, 5}, {36, 3, 5}, {36, 4, 5}, {24, 4, 5}, kNegZ);
  obj.part("bridge_railing_north", "bridge");
  obj.quad({24, 3, 7.5}, {36, 3, 7.5}, {36, 4, 7.5}, {24, 4, 7.5}, kPosZ);
  // Ramp down from the bridge's east end to the ground: one sloped quad at
  // 20 degrees (3 m over 8.24 m).
  obj.part("ramp", "ramps");
  {
    const double run = 3.0 / std::tan(20.0 * kPi / 180.0);
    obj.quad({36, 3, 5}, {36 + run, 0, 5}, {36 + run, 0, 7.5}, {36, 3, 7.5}, kUp);
  }

  // Room B: open on its south side, three walls facing in and a roof quad
  // (facing up, overhanging the walls) 3.2 m up; a crate inside.
  obj.part("room_b_wall_north", "walls");
  obj.quad({30, 0, 36}, {40, 0, 36}, {40, 3.2, 36}, {30, 3.2, 36}, kNegZ);
  obj.part("room_b_wall_west", "walls");
  obj.quad({30, 0, 28}, {30, 0, 36}, {30, 3.2, 36}, {30, 3.2, 28}, kPosX);
  obj.part("room_b_wall_east", "walls");
  obj.quad({40, 0, 28}, {40, 0, 36}, {40, 3.2, 36}, {40, 3.2, 28}, kNegX);
  obj.part("room_b_roof", "roofs");
  obj.flat(29.8, 27.5, 40.2, 36.2, 3.2, kUp);
  obj.part("room_b_crate", "props");
  obj.box({37, 0, 33}, {38.2, 1.2, 34.2});

  // Loose props: a crate on the ground, a crate floating at head height (it
  // blocks), a lamp floating high (walk under it) and a pillar.
  obj.part("crate_outside", "props");
  obj.box({16, 0, 30}, {17, 1, 31});
  obj.part("floating_crate_low", "props");
  obj.box({20, 1.0, 22}, {21.5, 2.0, 23.5});
  obj.part("floating_lamp_high", "props");
  obj.box({8, 4.0, 26}, {9, 4.6, 27});
  obj.part("pillar", "props");
  obj.box({14.6, 0, 24.6}, {15.4, 5, 25.4});
  return obj;
}

// --- soup_storeys.obj ---------------------------------------------------------

Obj soup_storeys() {
  Obj obj(
      "# soup_storeys.obj: a three-storey building on open ground as a triangle soup (40 x 30 m).\n"
      "# Generated by tests/levels/make_levels.cpp; do not edit. y up, metres.\n"
      "# Artist errors on purpose: floor_1_room_west and floor_2_south_strip face down,\n"
      "# floor_2_west_duplicate repeats floor_2_west.\n");
  const double storey = 3.5, top = 3 * storey;
  const double x0 = 10, x1 = 30, z0 = 8, z1 = 22;  // the building's footprint

  // Ground around the building: four one-sided quads, the footprint left out.
  obj.part("ground", "ground");
  obj.flat(0, 0, 40, z0, 0.0, kUp);
  obj.flat(0, z1, 40, 30, 0.0, kUp);
  obj.flat(0, z0, x0, z1, 0.0, kUp);
  obj.flat(x1, z0, 40, z1, 0.0, kUp);

  // Ramps at 20 degrees (3.5 m over 9.6 m). Ramp 1: storey 0 -> 1 along the
  // north wall, rising east; ramp 2: storey 1 -> 2 along the east wall,
  // rising north.
  const double run = 9.6;
  obj.part("ramp_0_to_1", "ramps");
  obj.quad({12, 0, 18.5}, {12 + run, storey, 18.5}, {12 + run, storey, 21}, {12, 0, 21}, kUp);
  obj.part("ramp_1_to_2", "ramps");
  obj.quad({26.5, storey, 9}, {29, storey, 9}, {29, 2 * storey, 9 + run}, {26.5, 2 * storey, 9 + run}, kUp);

  // Storey floors, one-sided, facing up (but for the two mistakes).
  obj.part("floor_0", "floors");
  obj.flat(x0, z0, x1, z1, 0.0, kUp);
  // Storey 1: a hole x 12 .. 21.6, z 18.5 .. 21 where ramp 1 arrives.
  // The west room is a dead end (its only door leads to the east room), so
  // its mistake decides no route between the storeys.
  obj.part("floor_1_room_west", "floors");
  obj.flat(x0, z0, 20, 18.5, storey, kDown);  // wound facing down by mistake
  obj.part("floor_1_room_east", "floors");
  obj.flat(20, z0, x1, 18.5, storey, kUp);
  obj.part("floor_1_north_strip", "floors");
  obj.flat(x0, 21, x1, z1, storey, kUp);
  obj.part("floor_1_beside_hole", "floors");
  obj.flat(x0, 18.5, 12, 21, storey, kUp);
  obj.flat(12 + run, 18.5, x1, 21, storey, kUp);
  // Storey 2: a hole x 26.5 .. 29, z 9 .. 18.6 where ramp 2 arrives.
  obj.part("floor_2_west", "floors");
  obj.flat(x0, z0, 26.5, z1, 2 * storey, kUp);
  obj.part("floor_2_west_duplicate", "floors");
  obj.flat(x0, z0, 26.5, z1, 2 * storey, kUp);  // the same quad again, coincident
  obj.part("floor_2_east_strip", "floors");
  obj.flat(29, z0, x1, z1, 2 * storey, kUp);
  obj.part("floor_2_south_strip", "floors");
  obj.flat(26.5, z0, 29, 9, 2 * storey, kDown);  // wound facing down by mistake
  obj.part("floor_2_north_strip", "floors");
  obj.flat(26.5, 9 + run, 29, z1, 2 * storey, kUp);
  obj.part("roof", "roofs");
  obj.flat(x0, z0, x1, z1, top, kUp);

  // Exterior walls: per storey and side, single quads facing out around
  // doors (2.4 x 2.5 m) and windows (sill 1 m, head 2.2 m).
  auto window = [](double u0, double u1, double floor) { return Opening{u0, u1, floor + 1.0, floor + 2.2}; };
  auto door = [](double u0, double u1, double floor) { return Opening{u0, u1, floor, floor + 2.5}; };
  for (int s = 0; s < 3; ++s) {
    const double f = s * storey, c = f + storey;
    const std::string n = std::to_string(s);
    obj.part("wall_south_" + n, "walls");  // z = 8, u along +x from x = 10
    if (s == 0)
      wall(obj, {x0, 0, z0}, {x1, 0, z0}, f, c, {door(4, 6.4, f), window(10, 12, f), window(15, 17, f)}, kNegZ);
    else
      wall(obj, {x0, 0, z0}, {x1, 0, z0}, f, c, {window(2, 4, f), window(7, 9, f), window(13, 15, f)}, kNegZ);
    obj.part("wall_north_" + n, "walls");  // z = 22
    if (s == 0)
      wall(obj, {x0, 0, z1}, {x1, 0, z1}, f, c, {window(3, 5, f), door(15, 17.4, f)}, kPosZ);
    else
      wall(obj, {x0, 0, z1}, {x1, 0, z1}, f, c, {window(3, 5, f), window(15, 17, f)}, kPosZ);
    obj.part("wall_west_" + n, "walls");  // x = 10, u along +z from z = 8
    wall(obj, {x0, 0, z0}, {x0, 0, z1}, f, c, {window(4, 6, f)}, kNegX);
    obj.part("wall_east_" + n, "walls");  // x = 30
    if (s == 0)
      wall(obj, {x1, 0, z0}, {x1, 0, z1}, f, c, {door(4, 6.4, f)}, kPosX);
    else
      wall(obj, {x1, 0, z0}, {x1, 0, z1}, f, c, {window(4, 6, f)}, kPosX);
  }
  // Storey 1: an interior wall between its two south rooms, a door in it.
  obj.part("wall_interior_1", "walls");
  wall(obj, {20, 0, z0}, {20, 0, 18.5}, storey, 2 * storey, {door(4, 6.2, storey)}, kPosX);

  // Props: crates on the ground floor and one upstairs, a table in the west room.
  obj.part("crate_0_a", "props");
  obj.box({24, 0, 10}, {25.2, 1.2, 11.2});
  obj.part("crate_0_b", "props");
  obj.box({25.3, 0, 10}, {26.5, 1.2, 11.2});
  obj.part("crate_2", "props");
  obj.box({14, 2 * storey, 12}, {15, 2 * storey + 1, 13});
  obj.part("table_1_top", "props");
  obj.box({13, storey + 0.72, 11}, {15, storey + 0.8, 12});
  for (int i = 0; i < 4; ++i) {
    const double x = i & 1 ? 14.87 : 13.05, z = i & 2 ? 11.87 : 11.05;
    obj.part("table_1_leg_" + std::to_string(i + 1), "props");
    obj.box({x, storey, z}, {x + 0.08, storey + 0.72, z + 0.08});
  }
  return obj;
}

// --- soup_yard.obj ------------------------------------------------------------

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// The yard's ground: gentle hills (under 15 degrees), flattened to 0 in the
// paved area x 3 .. 25, z 1 .. 10, and a 50 degree bank x 31.25 .. 33.75 up
// to a plateau 2.98 m higher.
double yard_height(double x, double z) {
  const double hills = 0.45 * std::sin(0.16 * x + 0.3) * std::cos(0.13 * z) + 0.35 * std::sin(0.19 * z + 1.1) +
                       0.2 * std::cos(0.23 * x - 0.17 * z);
  const double dx = std::max({3.0 - x, x - 25.0, 0.0}), dz = std::max({1.0 - z, z - 10.0, 0.0});
  const double paved = 1.0 - smoothstep(0.0, 8.0, std::sqrt(dx * dx + dz * dz));
  const double bank = std::tan(50.0 * kPi / 180.0) * std::clamp(x - 31.25, 0.0, 2.5);
  return (1.0 - paved) * (hills - 0.35 * std::sin(1.1)) + bank;
}

Obj soup_yard(double* max_gentle_slope) {
  Obj obj(
      "# soup_yard.obj: an outdoor yard on uneven ground as a triangle soup (50 x 40 m).\n"
      "# Generated by tests/levels/make_levels.cpp; do not edit. y up, metres.\n");
  constexpr double kSpacing = 1.25;
  constexpr int kNx = 40, kNz = 32;  // 50 x 40 m
  obj.part("ground_heightfield", "ground");
  {
    std::vector<int> v(size_t(kNx + 1) * (kNz + 1));
    std::vector<dvec3> p(v.size());
    for (int j = 0; j <= kNz; ++j) {
      for (int i = 0; i <= kNx; ++i) {
        const double x = i * kSpacing, z = j * kSpacing;
        // Rounded as written, so the slopes below are those of the file.
        const dvec3 q(x, std::stod(number(yard_height(x, z))), z);
        p[size_t(j) * (kNx + 1) + i] = q;
        v[size_t(j) * (kNx + 1) + i] = obj.vertex(q);
      }
    }
    *max_gentle_slope = 0.0;
    auto tri = [&](size_t a, size_t b, size_t c, bool bank) {
      obj.face({v[a], v[b], v[c]});
      const dvec3 n = glm::normalize(glm::cross(p[b] - p[a], p[c] - p[a]));
      if (!bank) *max_gentle_slope = std::max(*max_gentle_slope, std::acos(n.y) * 180.0 / kPi);
    };
    for (int j = 0; j < kNz; ++j) {
      for (int i = 0; i < kNx; ++i) {
        const size_t a = size_t(j) * (kNx + 1) + i, b = a + 1, c = a + kNx + 1, d = c + 1;
        const bool bank = i == 25 || i == 26;  // x 31.25 .. 33.75
        // Counter-clockwise seen from above (+y): a, c, d then a, d, b; the
        // diagonal alternates for a less directional mesh.
        if ((i + j) % 2 == 0) {
          tri(a, c, d, bank);
          tri(a, d, b, bank);
        } else {
          tri(a, c, b, bank);
          tri(b, c, d, bank);
        }
      }
    }
  }

  // A raised sidewalk along the paved area's south side: a one-sided top
  // 0.4 m over the flat road, its curb face and ends single quads facing out.
  obj.part("sidewalk_top", "curb");
  obj.flat(4, 1.5, 24, 4.5, 0.4, kUp);
  obj.part("curb_face", "curb");
  obj.quad({4, -0.1, 4.5}, {24, -0.1, 4.5}, {24, 0.4, 4.5}, {4, 0.4, 4.5}, kPosZ);
  obj.quad({4, -0.1, 1.5}, {4, -0.1, 4.5}, {4, 0.4, 4.5}, {4, 0.4, 1.5}, kNegX);
  obj.quad({24, -0.1, 1.5}, {24, -0.1, 4.5}, {24, 0.4, 4.5}, {24, 0.4, 1.5}, kPosX);
  obj.quad({4, -0.1, 1.5}, {24, -0.1, 1.5}, {24, 0.4, 1.5}, {4, 0.4, 1.5}, kNegZ);

  // Low walls: single quads standing on the ground (sunk 0.2 m under its
  // lowest point), their tops 0.5 m (steppable) or 1.2 m over its highest.
  auto low_wall = [&](const std::string& name, dvec3 a, dvec3 b, double height) {
    double lo = 1e9, hi = -1e9;
    for (int k = 0; k <= 20; ++k) {
      const dvec3 p = a + (b - a) * (k / 20.0);
      lo = std::min(lo, yard_height(p.x, p.z));
      hi = std::max(hi, yard_height(p.x, p.z));
    }
    obj.part(name, "walls");
    const dvec3 along = glm::normalize(b - a);
    const dvec3 facing(-along.z, 0.0, along.x);
    obj.quad({a.x, lo - 0.2, a.z}, {b.x, lo - 0.2, b.z}, {b.x, hi + height, b.z}, {a.x, hi + height, a.z}, facing);
  };
  low_wall("low_wall_0_5m", {8, 0, 14}, {14, 0, 14}, 0.5);
  low_wall("low_wall_1_2m_a", {17, 0, 15}, {17, 0, 23}, 1.2);
  low_wall("low_wall_1_2m_b", {36, 0, 10}, {44, 0, 13}, 1.2);

  // A fence along z = 27 of 2 m panels 1.4 m high, single quads, with gaps
  // of 0.5 m (too narrow for an agent of radius 0.6), 1 m and 2.5 m.
  {
    const double gaps[] = {0.5, 2.5, 0.5, 1.0, 0.5, 2.5, 0.5, 0.0};
    double x = 3.0;
    int panel = 0;
    for (double gap : gaps) {
      double lo = 1e9, hi = -1e9;
      for (int k = 0; k <= 8; ++k) {
        lo = std::min(lo, yard_height(x + 0.25 * k, 27));
        hi = std::max(hi, yard_height(x + 0.25 * k, 27));
      }
      obj.part("fence_panel_" + std::to_string(++panel), "fence");
      obj.quad({x, lo - 0.2, 27}, {x + 2, lo - 0.2, 27}, {x + 2, hi + 1.4, 27}, {x, hi + 1.4, 27}, kNegZ);
      x += 2.0 + gap;
    }
  }

  // Rocks: closed, outward-facing, low-poly ellipsoids (8 segments, 5
  // rings) with a fixed bumpy radius, sunk a little into the ground: their
  // tops 0.75 radius over their centre's ground (1 .. 1.5 m: too high to
  // climb, but for the small one).
  auto rock = [&](const std::string& name, double cx, double cz, double radius, int seed) {
    obj.part(name, "rocks");
    constexpr int kSeg = 8, kRing = 5;
    const dvec3 centre(cx, yard_height(cx, cz) - 0.15 * radius, cz);
    const int bottom = obj.vertex(centre - dvec3(0, 0.9 * radius, 0));
    std::vector<int> ring_start;
    for (int r = 1; r < kRing; ++r) {
      ring_start.push_back(0);
      const double phi = kPi * r / kRing;  // from the bottom
      for (int s = 0; s < kSeg; ++s) {
        const double theta = 2 * kPi * s / kSeg;
        const double bump = 1.0 + 0.15 * std::sin(3.7 * (s + 1) * (r + seed));
        const dvec3 p = centre + radius * bump *
                                     dvec3(std::sin(phi) * std::cos(theta), -0.9 * std::cos(phi),
                                           std::sin(phi) * std::sin(theta));
        const int id = obj.vertex(p);
        if (s == 0) ring_start.back() = id;
      }
    }
    const int top = obj.vertex(centre + dvec3(0, 0.9 * radius, 0));
    auto at = [&](int ring, int s) { return ring_start[size_t(ring)] + (s % kSeg); };
    // Outward: seen from outside, counter-clockwise. theta grows from +x
    // towards +z, which seen from above (+y) is clockwise.
    for (int s = 0; s < kSeg; ++s) obj.face({bottom, at(0, s), at(0, s + 1)});
    for (int r = 0; r + 1 < kRing - 1; ++r)
      for (int s = 0; s < kSeg; ++s) {
        obj.face({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
        obj.face({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
      }
    for (int s = 0; s < kSeg; ++s) obj.face({top, at(kRing - 2, s + 1), at(kRing - 2, s)});
  };
  rock("rock_1", 10, 20, 1.6, 1);
  rock("rock_2", 22, 33, 2.0, 2);
  rock("rock_3", 40, 22, 1.4, 3);
  rock("rock_4_small", 45, 34, 0.8, 4);  // 0.6 m over the ground: climbable
  return obj;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTDIR\n  writes OUTDIR/soup_rooms.obj, soup_storeys.obj, soup_yard.obj\n",
                 argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  double slope = 0.0;
  const Obj levels[] = {soup_rooms(), soup_storeys(), soup_yard(&slope)};
  const char* names[] = {"soup_rooms.obj", "soup_storeys.obj", "soup_yard.obj"};
  for (int i = 0; i < 3; ++i) {
    const std::string path = dir + "/" + names[i];
    if (!levels[i].write(path)) {
      std::fprintf(stderr, "make_levels: cannot write %s\n", path.c_str());
      return 1;
    }
    std::printf("%s: %zu triangles\n", path.c_str(), levels[i].triangles());
  }
  std::printf("soup_yard.obj: steepest ground triangle off the bank %.1f degrees\n", slope);
  return 0;
}
