// Game queries (ldc/query.h) against Embree 3 (issue 5): ray-cast throughput
// on random and camera rays, build and per-edit costs, accuracy against the
// source mesh, and sphere casts / overlaps, on four meshes at 128 and 256
// cells and on the default landscape (h = 0.2 m), all in the same run.
//
// Every throughput figure comes from one harness: std::threads pulling
// 4096-ray chunks from an atomic counter, one single-ray call per ray
// (Queries::ray_cast, rtcIntersect1), as shared/PEERS.md measured Embree.
//
// Usage: bench_query [--quick] [--rays N] [--scenes bunny,spot,fandisk,rocker,landscape]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <embree3/rtcore.h>

#include "bench_common.h"
#include "contour/contour.h"
#include "csg/csg.h"
#include "embree/embree_ray.h"
#include "ldc/build.h"
#include "ldc/query.h"
#include "ldc/terrain.h"
#include "meshio/meshio.h"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// --- Embree -----------------------------------------------------------------------

void embree_error(void*, RTCError code, const char* text) {
  std::fprintf(stderr, "embree error %d: %s\n", int(code), text ? text : "");
  std::exit(1);
}

struct EmbreeDevice {
  RTCDevice device = nullptr;
  explicit EmbreeDevice(const char* config) {
    device = rtcNewDevice(config);
    if (!device) {
      std::fprintf(stderr, "rtcNewDevice failed\n");
      std::exit(1);
    }
    rtcSetDeviceErrorFunction(device, embree_error, nullptr);
  }
  ~EmbreeDevice() { rtcReleaseDevice(device); }
};

// A committed Embree scene of one triangle mesh, with the triangles' outward
// normals (counter-clockwise) to tell front from back hits.
struct EmbreeMesh {
  RTCScene scene = nullptr;
  std::vector<glm::vec3> face_normal;
  double commit_ms = 0.0;
  EmbreeMesh() = default;
  EmbreeMesh(const EmbreeMesh&) = delete;
  EmbreeMesh& operator=(const EmbreeMesh&) = delete;
  ~EmbreeMesh() {
    if (scene) rtcReleaseScene(scene);
  }
};

// Builds a scene; returns the rtcCommitScene time in ms.
double make_embree_scene(RTCDevice dev, const std::vector<glm::dvec3>& positions,
                         const std::vector<glm::uvec3>& triangles, RTCScene* out) {
  RTCScene scene = rtcNewScene(dev);
  RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), positions.size()));
  for (size_t i = 0; i < positions.size(); ++i) {
    v[3 * i + 0] = float(positions[i].x);
    v[3 * i + 1] = float(positions[i].y);
    v[3 * i + 2] = float(positions[i].z);
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), triangles.size()));
  for (size_t i = 0; i < triangles.size(); ++i) {
    idx[3 * i + 0] = triangles[i].x;
    idx[3 * i + 1] = triangles[i].y;
    idx[3 * i + 2] = triangles[i].z;
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  auto t0 = Clock::now();
  rtcCommitScene(scene);
  const double ms = seconds_since(t0) * 1e3;
  *out = scene;
  return ms;
}

// Median commit time of `reps` fresh scenes; keeps the last one in `mesh`.
void build_embree(RTCDevice dev, const std::vector<glm::dvec3>& positions, const std::vector<glm::uvec3>& triangles,
                  int reps, EmbreeMesh* mesh) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    if (mesh->scene) rtcReleaseScene(mesh->scene);
    mesh->scene = nullptr;
    t.push_back(make_embree_scene(dev, positions, triangles, &mesh->scene));
  }
  std::sort(t.begin(), t.end());
  mesh->commit_ms = t[t.size() / 2];
  mesh->face_normal.resize(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const glm::dvec3 &a = positions[triangles[i].x], &b = positions[triangles[i].y], &c = positions[triangles[i].z];
    mesh->face_normal[i] = glm::vec3(glm::cross(b - a, c - a));
  }
}

double median_commit_ms(RTCDevice dev, const std::vector<glm::dvec3>& positions,
                        const std::vector<glm::uvec3>& triangles, int reps) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    RTCScene s = nullptr;
    t.push_back(make_embree_scene(dev, positions, triangles, &s));
    rtcReleaseScene(s);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// --- Rays and the harness ----------------------------------------------------------

// One answer: kind 0 = miss, 1 = hit from outside, 2 = the ray started inside
// (ldc: started_inside; Embree: its first hit is a back face).
struct Answer {
  double t = 0.0;
  uint32_t prim = 0;
  uint8_t kind = 0;
};

struct RaySet {
  const char* name;
  std::vector<ldc::Ray> rays;
};

glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    glm::dvec3 v(n(rng), n(rng), n(rng));
    const double l = glm::length(v);
    if (l > 1e-12) return v / l;
  }
}

RaySet random_rays(const glm::dvec3& lo, const glm::dvec3& hi, size_t n, uint64_t seed) {
  RaySet s{"random", {}};
  s.rays.resize(n);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (ldc::Ray& r : s.rays) {
    r.origin = lo + glm::dvec3(u(rng), u(rng), u(rng)) * (hi - lo);
    r.direction = random_unit(rng);
  }
  return s;
}

// Pinhole camera 1.5 diag from the box centre along (0.4, 0.6, 0.7), looking
// at the centre; the square image just frames `frame` (every point inside it).
RaySet camera_rays(const glm::dvec3& lo, const glm::dvec3& hi, const std::vector<glm::dvec3>& frame,
                   const glm::dvec3& up_hint, int width) {
  RaySet s{"camera", {}};
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double diag = glm::length(hi - lo);
  const glm::dvec3 eye = centre + 1.5 * diag * glm::normalize(glm::dvec3(0.4, 0.6, 0.7));
  const glm::dvec3 fwd = glm::normalize(centre - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, up_hint));
  const glm::dvec3 up = glm::cross(right, fwd);
  double half = 0.0;
  for (const glm::dvec3& p : frame) {
    const glm::dvec3 q = p - eye;
    const double z = glm::dot(q, fwd);
    half = std::max({half, std::abs(glm::dot(q, right) / z), std::abs(glm::dot(q, up) / z)});
  }
  s.rays.resize(size_t(width) * width);
  for (int j = 0; j < width; ++j)
    for (int i = 0; i < width; ++i) {
      const double sx = ((i + 0.5) / width * 2.0 - 1.0) * half, sy = (1.0 - (j + 0.5) / width * 2.0) * half;
      ldc::Ray& r = s.rays[size_t(j) * width + i];
      r.origin = eye;
      r.direction = glm::normalize(fwd + sx * right + sy * up);
    }
  return s;
}

// Runs f(i) for i in [begin, end) on `threads` std::threads pulling 4096-ray
// chunks from an atomic counter; returns the wall time in seconds.
double run_chunks(size_t begin, size_t end, int threads, const std::function<void(size_t, size_t)>& f) {
  std::atomic<size_t> next{begin};
  auto worker = [&] {
    for (;;) {
      const size_t b = next.fetch_add(4096);
      if (b >= end) break;
      f(b, std::min(end, b + 4096));
    }
  };
  auto t0 = Clock::now();
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  return seconds_since(t0);
}

double ldc_pass(const ldc::Queries& q, const std::vector<ldc::Ray>& rays, size_t begin, size_t end, int threads,
                std::vector<Answer>* out) {
  return run_chunks(begin, end, threads, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      ldc::Result<ldc::RayHit> r = q.ray_cast(rays[i]);
      if (!r.ok()) {
        std::fprintf(stderr, "ray_cast: %s\n", r.status().to_string().c_str());
        std::exit(1);
      }
      if (out) {
        Answer& a = (*out)[i];
        a.t = r->distance;
        a.kind = !r->hit ? 0 : r->started_inside ? 2 : 1;
      }
    }
  });
}

double embree_pass(const EmbreeMesh& m, const std::vector<ldc::Ray>& rays, size_t begin, size_t end, int threads,
                   std::vector<Answer>* out) {
  const double secs = run_chunks(begin, end, threads, [&](size_t b, size_t e) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (size_t i = b; i < e; ++i) {
      const ldc::Ray& ray = rays[i];
      RTCRayHit rh = ldc::test::embree_ray(ray.origin, ray.direction);
      rtcIntersect1(m.scene, &ctx, &rh);
      if (out) {
        Answer& a = (*out)[i];
        a.kind = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0 : 1;
        a.t = rh.ray.tfar;
        a.prim = rh.hit.primID;
      }
    }
  });
  if (out) {
    // Front or back face, outside the timing (directions are unit).
    for (size_t i = begin; i < end; ++i) {
      Answer& a = (*out)[i];
      if (a.kind == 1 && glm::dot(glm::dvec3(m.face_normal[a.prim]), rays[i].direction) > 0.0) a.kind = 2;
    }
  }
  return secs;
}

size_t hits(const std::vector<Answer>& a) {
  size_t n = 0;
  for (const Answer& x : a) n += x.kind != 0;
  return n;
}

// --- Scenes -------------------------------------------------------------------------

struct Scene {
  std::string name;
  int cells = 0;  // 0: the landscape
  bool has_source = false;
  ldc::TriangleMesh source;
  glm::dvec3 lo{0.0}, hi{0.0};  // box of the random origins
  std::vector<glm::dvec3> frame;
  glm::dvec3 up{0.0, 1.0, 0.0};
  double h = 0.0;
  double dig_radius = 0.0;
  ldc::World world;
  double build_ms = 0.0;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[size_t(p * double(v.size() - 1) + 0.5)];
}

struct Accuracy {
  size_t rays = 0, agree = 0, both_inside = 0, inside_agree = 0, compared = 0, within_half = 0;
  double median = 0, p99 = 0, worst = 0;
};

// ldc against a reference: hit/miss agreement; start-inside agreement; for
// rays both hit from outside, |t_ldc - t_ref| in h.
Accuracy compare(const std::vector<Answer>& ldc_a, const std::vector<Answer>& ref, double h) {
  Accuracy acc;
  std::vector<double> err;
  for (size_t i = 0; i < ldc_a.size(); ++i) {
    const Answer &a = ldc_a[i], &b = ref[i];
    ++acc.rays;
    acc.agree += (a.kind != 0) == (b.kind != 0);
    acc.inside_agree += (a.kind == 2) == (b.kind == 2);
    if (a.kind == 1 && b.kind == 1) {
      const double e = std::abs(a.t - b.t) / h;
      err.push_back(e);
      acc.within_half += e <= 0.5;
    }
  }
  acc.compared = err.size();
  acc.median = percentile(err, 0.5);
  acc.p99 = percentile(err, 0.99);
  acc.worst = err.empty() ? 0.0 : *std::max_element(err.begin(), err.end());
  return acc;
}

struct Options {
  bool quick = false;
  size_t rays = 1000000;
  size_t rays_256 = 500000;
  size_t contact_queries = 100000;
  size_t contact_queries_256 = 25000;
  double contact_cap_s = 12.0;
  std::vector<std::string> scenes = {"bunny", "spot", "fandisk", "rocker", "landscape"};
};

// Table rows, printed together at the end.
struct Rows {
  std::vector<std::string> throughput, build, edit, accuracy, contact;
  std::vector<std::string> notes;
} rows;

std::string fmt_rate(double mrays) { return fmt(mrays >= 10 ? "%.1f" : "%.2f", mrays); }

// Derives (or re-checks) the cache of every chunk of the scene.
void warm_all(const ldc::Queries& q) {
  const ldc::World& world = q.world();
  const glm::ivec3 a = world.chunk_origin() - 1, b = world.chunk_origin() + world.chunk_dims() - 1;
  for (int z = a.z; z <= b.z; ++z)
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) (void)q.cell_index({x, y, z});
}

std::string load_average() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f) return "unknown";
  char buf[128] = {0};
  const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  std::string s(buf, n);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

void scene_bench(Scene& sc, const Options& opt, const EmbreeDevice& dev, const EmbreeDevice& dev1) {
  const size_t n_rays = sc.cells >= 256 ? opt.rays_256 : opt.rays;
  std::ostringstream label;
  label << sc.name << " | " << (sc.cells ? std::to_string(sc.cells) : std::string("h 0.2 m"));
  const std::string tag = label.str();
  std::fprintf(stderr, "[bench_query] %s: %zu rays\n", tag.c_str(), n_rays);
  const ldc::World& world = sc.world;
  const ldc::WorldStats wstats = world.stats();

  // Contoured mesh, Embree scenes.
  auto t0 = Clock::now();
  ldc::ContourMesh contour = ldc::contour_world(world).value();
  const double contour_ms = seconds_since(t0) * 1e3;
  EmbreeMesh e_src, e_con;
  const int commit_reps = opt.quick ? 3 : 7;
  if (sc.has_source) build_embree(dev.device, sc.source.positions, sc.source.triangles, commit_reps, &e_src);
  build_embree(dev.device, contour.positions, contour.triangles, commit_reps, &e_con);
  const double src_commit1 =
      sc.has_source ? median_commit_ms(dev1.device, sc.source.positions, sc.source.triangles, commit_reps) : 0.0;
  const double con_commit1 = median_commit_ms(dev1.device, contour.positions, contour.triangles, commit_reps);

  // ldc: the cache for the whole scene, on a fresh Queries, one thread.
  std::vector<double> derive;
  ldc::QueryCacheStats cache;
  for (int r = 0; r < (opt.quick ? 1 : 3); ++r) {
    ldc::Queries fresh(world);
    auto s0 = Clock::now();
    warm_all(fresh);
    derive.push_back(seconds_since(s0) * 1e3);
    cache = fresh.cache_stats();
  }
  std::sort(derive.begin(), derive.end());
  {
    std::ostringstream r;
    r << "| " << tag << " | " << fmt("%.4g", sc.h) << " | "
      << (sc.has_source ? std::to_string(sc.source.triangles.size()) : std::string("-")) << " | "
      << contour.triangles.size() << " | " << fmt("%.1f", sc.build_ms) << " | " << fmt("%.1f", contour_ms) << " | "
      << fmt("%.2f", derive[derive.size() / 2]) << " | " << cache.chunks_indexed << " | "
      << fmt("%.0f", double(cache.bytes) / 1024.0) << " | " << wstats.points << " | "
      << fmt("%.2f", wstats.points ? double(cache.bytes) / double(wstats.points) : 0.0) << " | "
      << fmt("%.2f", wstats.bytes_per_point()) << " | "
      << (sc.has_source ? fmt("%.2f", e_src.commit_ms) + " / " + fmt("%.2f", src_commit1) : std::string("-"))
      << " | " << fmt("%.2f", e_con.commit_ms) << " / " << fmt("%.2f", con_commit1) << " |";
    rows.build.push_back(r.str());
  }

  // Ray sets.
  const glm::dvec3 lo = sc.lo, hi = sc.hi;
  std::vector<RaySet> sets;
  sets.push_back(random_rays(lo, hi, n_rays, 0x5eed0000u + uint64_t(sc.cells)));
  const int width = n_rays >= 1000000 ? 1000 : int(std::lround(std::sqrt(double(n_rays))));
  sets.push_back(camera_rays(lo, hi, sc.frame, sc.up, width));

  double ldc_random_1t = 0, src_random_1t = 0, con_random_1t = 0;
  std::vector<Answer> ldc_random, src_random, con_random;
  for (RaySet& set : sets) {
    const size_t n = set.rays.size();
    std::vector<Answer> a_ldc(n), a_src(sc.has_source ? n : 0), a_con(n);
    ldc::Queries q(world);
    const double cold = ldc_pass(q, set.rays, 0, n, 1, &a_ldc);  // first pass: derives the cache
    const double l1 = ldc_pass(q, set.rays, 0, n, 1, nullptr);
    const double l2 = ldc_pass(q, set.rays, 0, n, 2, nullptr);
    double s1 = 0, s2 = 0;
    if (sc.has_source) {
      s1 = embree_pass(e_src, set.rays, 0, n, 1, &a_src);
      s2 = embree_pass(e_src, set.rays, 0, n, 2, nullptr);
    }
    const double c1 = embree_pass(e_con, set.rays, 0, n, 1, &a_con);
    const double c2 = embree_pass(e_con, set.rays, 0, n, 2, nullptr);
    auto mr = [n](double secs) { return double(n) / secs * 1e-6; };
    auto pct = [n](size_t k) { return fmt("%.1f%%", 100.0 * double(k) / double(n)); };
    std::ostringstream r;
    r << "| " << tag << " | " << set.name << " | " << n << " | " << fmt_rate(mr(cold)) << " | " << fmt_rate(mr(l1))
      << " | " << fmt_rate(mr(l2)) << " | " << (sc.has_source ? fmt_rate(mr(s1)) : "-") << " | "
      << (sc.has_source ? fmt_rate(mr(s2)) : "-") << " | " << fmt_rate(mr(c1)) << " | " << fmt_rate(mr(c2)) << " | "
      << pct(hits(a_ldc)) << " / " << (sc.has_source ? pct(hits(a_src)) : "-") << " / " << pct(hits(a_con))
      << " | ";
    const double ref1 = sc.has_source ? s1 : c1;
    const double ratio = ref1 / l1;  // rates: (n/l1)/(n/ref1)
    r << fmt("%.3f", ratio) << (sc.has_source ? "" : " (contoured)");
    if (std::strcmp(set.name, "random") == 0) r << (ratio >= 0.5 ? " (>= 0.5: met)" : " (>= 0.5: missed)");
    r << " |";
    rows.throughput.push_back(r.str());
    if (std::strcmp(set.name, "random") == 0) {
      ldc_random_1t = mr(l1);
      src_random_1t = sc.has_source ? mr(s1) : 0.0;
      con_random_1t = mr(c1);
      ldc_random = std::move(a_ldc);
      src_random = std::move(a_src);
      con_random = std::move(a_con);
    }
  }

  // Accuracy of the random rays.
  auto acc_row = [&](const char* against, const Accuracy& a) {
    std::ostringstream r;
    r << "| " << tag << " | " << against << " | " << a.rays << " | " << fmt("%.3f", 100.0 * a.agree / a.rays)
      << " | " << fmt("%.3f", 100.0 * a.inside_agree / a.rays) << " | " << a.compared << " | "
      << fmt("%.3f", a.median) << " | " << fmt("%.3f", a.p99) << " | " << fmt("%.1f", a.worst) << " | "
      << fmt("%.2f", a.compared ? 100.0 * a.within_half / a.compared : 0.0)
      << (a.compared && 100.0 * a.within_half / a.compared >= 99.0 ? " (met)" : " (missed)") << " |";
    rows.accuracy.push_back(r.str());
  };
  if (sc.has_source) acc_row("source mesh", compare(ldc_random, src_random, sc.h));
  acc_row(sc.has_source ? "contoured mesh" : "contoured mesh (no source)", compare(ldc_random, con_random, sc.h));

  // Sphere casts and overlaps, radius 2h, one thread, warm cache.
  {
    ldc::Queries q(world);
    warm_all(q);
    const size_t nq = sc.cells >= 256 ? opt.contact_queries_256 : opt.contact_queries;
    RaySet casts = random_rays(lo, hi, nq, 0xca57u + uint64_t(sc.cells));
    const double radius = 2.0 * sc.h;
    // Runs query(i) for i = 0.. until nq or the time cap; "ran | per s | positive %", or n/a on an error.
    auto timed = [&](const char* what, const std::function<ldc::Result<bool>(size_t)>& query) -> std::string {
      size_t positive = 0, done = 0;
      auto s0 = Clock::now();
      for (; done < nq; ++done) {
        ldc::Result<bool> r = query(done);
        if (!r.ok()) {
          rows.notes.push_back(std::string(what) + " (" + tag + "), query " + std::to_string(done) + ": " +
                               r.status().to_string());
          return "n/a | n/a | n/a";
        }
        positive += r.value();
        if ((done & 255) == 255 && seconds_since(s0) > opt.contact_cap_s) {
          ++done;
          break;
        }
      }
      const double secs = seconds_since(s0);
      return std::to_string(done) + " | " + fmt("%.0f", double(done) / secs) + " | " +
             fmt("%.1f%%", 100.0 * double(positive) / double(done));
    };
    const std::string cast_cell = timed("sphere_cast", [&](size_t i) -> ldc::Result<bool> {
      ldc::Result<ldc::RayHit> r = q.sphere_cast(casts.rays[i], radius);
      if (!r.ok()) return r.status();
      return r->hit;
    });
    const std::string overlap_cell = timed("overlap", [&](size_t i) -> ldc::Result<bool> {
      ldc::Result<ldc::Overlap> r = q.overlap(casts.rays[i].origin, radius);
      if (!r.ok()) return r.status();
      return r->overlaps;
    });
    std::ostringstream r;
    r << "| " << tag << " | " << fmt("%.4g", radius) << " | " << cast_cell << " | " << overlap_cell << " |";
    rows.contact.push_back(r.str());
  }

  // Per-edit cost: sphere digs at surface points (contour vertices; on the
  // landscape, upward-facing ones), each undone afterwards (untimed).
  {
    ldc::WorldEditor ed(std::move(sc.world));
    ldc::Queries q(ed.world());
    const std::vector<ldc::Ray>& rays = sets[0].rays;
    const size_t batch = std::min<size_t>(10000, rays.size());
    warm_all(q);
    std::vector<size_t> candidates;
    for (size_t i = 0; i < contour.positions.size(); ++i)
      if (sc.has_source || contour.normals[i].z > 0.7f) candidates.push_back(i);
    std::mt19937_64 rng(0xd16u + uint64_t(sc.cells));
    const int digs = opt.quick ? 3 : 7;
    std::vector<double> eager_ms, extra_ms, commit_ms, recontour_ms;
    std::vector<size_t> changed_counts, derived_counts;
    for (int d = 0; d < digs; ++d) {
      const glm::dvec3 p = contour.positions[candidates[rng() % candidates.size()]];
      std::vector<double> warm;
      for (int k = 0; k < 3; ++k) warm.push_back(ldc_pass(q, rays, 0, batch, 1, nullptr));
      std::sort(warm.begin(), warm.end());
      ldc::EditReceipt receipt = ed.apply(ldc::Brush::sphere(p, sc.dig_radius), ldc::EditOp::kSubtract).value();
      (void)ed.take_dirty();
      std::set<std::tuple<int, int, int>> touched;
      for (const glm::ivec3& c : receipt.changed_chunks)
        for (const glm::ivec3& o : {glm::ivec3(0, 0, 0), glm::ivec3(-1, 0, 0), glm::ivec3(0, -1, 0),
                                    glm::ivec3(0, 0, -1), glm::ivec3(-1, -1, 0), glm::ivec3(0, -1, -1),
                                    glm::ivec3(-1, 0, -1)})
          touched.insert({c.x + o.x, c.y + o.y, c.z + o.z});
      auto e0 = Clock::now();
      for (const auto& [x, y, z] : touched) (void)q.cell_index({x, y, z});
      eager_ms.push_back(seconds_since(e0) * 1e3);
      const double after = ldc_pass(q, rays, 0, batch, 1, nullptr);
      extra_ms.push_back(std::max(0.0, after - warm[1]) * 1e3);
      changed_counts.push_back(receipt.changed_chunks.size());
      derived_counts.push_back(touched.size());
      // Embree: the re-contoured mesh, committed afresh (default device).
      auto c0 = Clock::now();
      ldc::ContourMesh edited = ldc::contour_world(ed.world()).value();
      recontour_ms.push_back(seconds_since(c0) * 1e3);
      commit_ms.push_back(median_commit_ms(dev.device, edited.positions, edited.triangles, 3));
      if (!ed.undo(receipt).ok()) std::abort();
      (void)ed.take_dirty();
      q.refresh();
      warm_all(q);
    }
    auto med = [](std::vector<double> v) { return percentile(std::move(v), 0.5); };
    std::vector<double> cc(changed_counts.begin(), changed_counts.end()),
        dc(derived_counts.begin(), derived_counts.end());
    const double ldc_rebuild = (med(eager_ms) + med(extra_ms)) * 1e-3;
    auto effective = [](double mrays, double rebuild_s) {
      return 10000.0 / (10000.0 / (mrays * 1e6) + rebuild_s) * 1e-6;
    };
    const double eff_ldc = effective(ldc_random_1t, ldc_rebuild);
    const double eff_con = effective(con_random_1t, med(commit_ms) * 1e-3);
    const double eff_src = sc.has_source ? effective(src_random_1t, e_src.commit_ms * 1e-3) : 0.0;
    std::ostringstream r;
    r << "| " << tag << " | " << fmt("%.4g", sc.dig_radius) << " | " << fmt("%.0f", med(cc)) << " | "
      << fmt("%.0f", med(dc)) << " | " << fmt("%.2f", med(eager_ms)) << " | " << fmt("%.2f", med(extra_ms)) << " | "
      << fmt("%.2f", med(commit_ms)) << " | " << (sc.has_source ? fmt("%.2f", e_src.commit_ms) : "-") << " | "
      << fmt("%.1f", med(recontour_ms)) << " | " << fmt_rate(eff_ldc) << " | " << fmt_rate(eff_con) << " | "
      << (sc.has_source ? fmt_rate(eff_src) : "-") << " | ";
    auto verdict = [](double ratio) { return fmt("%.2f", ratio) + (ratio >= 3.0 ? " (met)" : " (missed)"); };
    r << verdict(eff_ldc / eff_con) << " | " << (sc.has_source ? verdict(eff_ldc / eff_src) : std::string("-"))
      << " |";
    rows.edit.push_back(r.str());
  }
}

void print_tables(const Options& opt) {
  std::printf("\n### Ray-cast throughput\n\n");
  std::printf(
      "Million rays per second; one single-ray call per ray (ldc `Queries::ray_cast`, Embree `rtcIntersect1`) from "
      "std::threads pulling 4096-ray chunks from an atomic counter. `random`: %zu rays (%zu at 256 cells), origins "
      "uniform in the mesh's bounding box (the landscape's solid bounds), directions uniform on the sphere, no "
      "distance limit. `camera`: a pinhole camera 1.5 diag from the box centre along (0.4, 0.6, 0.7), a square "
      "image (1000x1000; %dx%d at 256 cells) just framing the source mesh's vertices (the landscape's solid bounds). "
      "ldc cold = the first pass on a fresh `Queries` (1 thread, derives the per-chunk cache); the 1- and 2-thread "
      "columns are warm passes. Embree src = the source mesh, Embree con = ldc's contoured mesh (contour_world). "
      "Ratio = ldc / Embree at 1 thread, against the source mesh (the contoured mesh on the landscape); target on "
      "random rays: >= 0.5.\n\n",
      opt.rays, opt.rays_256, int(std::lround(std::sqrt(double(opt.rays_256)))),
      int(std::lround(std::sqrt(double(opt.rays_256)))));
  std::fputs(
      "| scene | cells | rays | n | ldc cold 1T | ldc 1T | ldc 2T | Embree src 1T | Embree src 2T | Embree con 1T | "
      "Embree con 2T | hit % ldc / src / con | ratio ldc/Embree 1T |\n",
      stdout);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& r : rows.throughput) std::printf("%s\n", r.c_str());

  std::printf("\n### Build costs\n\n");
  std::printf(
      "ldc build = build_from_mesh / build_terrain (TBB, 2 threads), median of %d. Cache = the per-chunk query "
      "bits for every chunk of the scene (`cell_index` on chunks chunk_origin()-1 .. chunk_origin()+chunk_dims()-1 "
      "on a fresh `Queries`, 1 thread, median of %d); its size from cache_stats(), per surface point "
      "(world.stats().points). Embree commit = rtcCommitScene, median of %d, default device (all cores) / device "
      "with threads=1. Contour ms = contour_world, for reference (Embree on the contoured mesh needs it after every "
      "edit).\n\n",
      opt.quick ? 1 : 3, opt.quick ? 1 : 3, opt.quick ? 3 : 7);
  std::printf(
      "| scene | cells | h | source tris | contour tris | ldc build ms | contour ms | cache derive ms | chunks "
      "indexed | cache KiB | points | cache B/point | world B/point | Embree src commit ms (all / 1T) | Embree con "
      "commit ms (all / 1T) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& r : rows.build) std::printf("%s\n", r.c_str());

  std::printf("\n### Per-edit cost\n\n");
  std::printf(
      "A sphere dig (WorldEditor::apply, kSubtract) of radius 0.05 diag (1 m on the landscape) centred on a "
      "contour vertex (an upward-facing one on the landscape); median of %d digs, each undone afterwards. ldc "
      "re-derive = `cell_index` on the changed chunks and their -x/-y/-z/-xy/-yz/-zx neighbours; ldc extra = the "
      "first 10,000-ray random pass after that, minus a warm one (the other chunks' validity checks after the "
      "world's stamp moved). Embree con rebuild = rtcCommitScene of the re-contoured mesh (default device, all "
      "cores; re-contouring itself, shown for reference, is not counted); Embree src = rtcCommitScene of the "
      "source mesh (what a mesh-based world would rebuild). Effective Mrays/s with one edit per 10,000 rays = "
      "10000 / (10000 / rate + rebuild s), rate = the 1-thread random rate above; for ldc rebuild = re-derive + "
      "extra. Target: ldc >= 3x Embree.\n\n",
      opt.quick ? 3 : 7);
  std::printf(
      "| scene | cells | dig radius | chunks changed | chunks re-derived | ldc re-derive ms | ldc extra ms | Embree "
      "con commit ms | Embree src commit ms | re-contour ms | eff. ldc | eff. Embree con | eff. Embree src | ldc / "
      "Embree con (>= 3) | ldc / Embree src (>= 3) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& r : rows.edit) std::printf("%s\n", r.c_str());

  std::printf("\n### Accuracy of random rays\n\n");
  std::printf(
      "ldc's random-ray answers against Embree on the source mesh and on ldc's own contoured mesh (the landscape "
      "has no source mesh: contoured only). hit/miss = both hit or both miss; start inside = both or neither "
      "say the ray starts inside (ldc: started_inside; Embree: the first hit is a back face). dt = |t_ldc - "
      "t_Embree| in cells h, over rays both hit from outside. Target: 99%% within h/2 against the source mesh.\n\n");
  std::fputs(
      "| scene | cells | against | rays | hit/miss agree % | start inside agree % | hits compared | median dt (h) | "
      "p99 dt (h) | max dt (h) | within h/2 % |\n",
      stdout);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& r : rows.accuracy) std::printf("%s\n", r.c_str());

  std::printf("\n### Sphere casts and overlaps\n\n");
  std::printf(
      "%zu random queries (%zu at 256 cells), 1 thread, warm cache (`warm_all`), radius 2h: sphere casts from "
      "origins uniform in the box along uniform directions (no distance limit), sphere overlaps centred at the same "
      "origins; each kind stops after %.0f s (the run columns say how many ran). n/a: the call returned an "
      "error (see the notes).\n\n",
      opt.contact_queries, opt.contact_queries_256, opt.contact_cap_s);
  std::fputs(
      "| scene | cells | radius | sphere casts run | sphere casts/s | cast hit % | overlaps run | overlaps/s | "
      "overlapping % |\n",
      stdout);
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& r : rows.contact) std::printf("%s\n", r.c_str());
  if (!rows.notes.empty()) {
    std::printf("\nNotes:\n\n");
    for (const std::string& n : rows.notes) std::printf("- %s\n", n.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  std::string data_dir = LDC_BENCH_DATA_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--quick") {
      opt.quick = true;
      opt.rays = 100000;
      opt.rays_256 = 40000;
      opt.contact_queries = 10000;
      opt.contact_queries_256 = 5000;
    } else if (s == "--rays" && i + 1 < argc) {
      opt.rays = std::stoul(argv[++i]);
      opt.rays_256 = std::min(opt.rays_256, opt.rays);
    } else if (s == "--scenes" && i + 1 < argc) {
      opt.scenes.clear();
      std::stringstream in(argv[++i]);
      for (std::string m; std::getline(in, m, ',');) opt.scenes.push_back(m);
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--rays N] [--scenes bunny,spot,fandisk,rocker,landscape]\n",
                   argv[0]);
      return 2;
    }
  }
  auto t_start = Clock::now();
  const std::string load_start = load_average();
  std::printf("# Game queries against Embree\n\n");
  ldc::bench::print_machine();
  std::printf("- Embree %d.%d.%d (rtcIntersect1, default scene flags and build quality)\n", RTC_VERSION_MAJOR,
              RTC_VERSION_MINOR, RTC_VERSION_PATCH);

  EmbreeDevice dev(nullptr), dev1("threads=1");
  struct Input {
    const char* key;
    const char* file;
  };
  const Input inputs[] = {{"bunny", "stanford-bunny.obj"}, {"spot", "spot.obj"}, {"fandisk", "fandisk.obj"},
                          {"rocker", "rocker-arm.obj"}};
  auto wanted = [&](const char* key) {
    return std::find(opt.scenes.begin(), opt.scenes.end(), key) != opt.scenes.end();
  };
  for (const Input& in : inputs) {
    if (!wanted(in.key)) continue;
    ldc::Result<ldc::TriangleMesh> mesh = ldc::load_mesh(data_dir + "/" + in.file);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s\n", mesh.status().to_string().c_str());
      return 1;
    }
    for (int cells : {128, 256}) {
      Scene sc;
      sc.name = in.file;
      sc.name = sc.name.substr(0, sc.name.size() - 4);
      sc.cells = cells;
      sc.has_source = true;
      sc.source = mesh.value();
      sc.lo = glm::dvec3(std::numeric_limits<double>::infinity());
      sc.hi = -sc.lo;
      for (const glm::dvec3& p : sc.source.positions) sc.lo = glm::min(sc.lo, p), sc.hi = glm::max(sc.hi, p);
      sc.frame = sc.source.positions;
      const glm::dvec3 ext = sc.hi - sc.lo;
      ldc::GridConfig grid;
      grid.cells = cells;
      std::vector<double> t;
      for (int r = 0; r < (opt.quick ? 1 : 3); ++r) {
        auto t0 = Clock::now();
        ldc::Result<ldc::World> w = ldc::build_from_mesh(sc.source, grid);
        t.push_back(seconds_since(t0) * 1e3);
        if (!w.ok()) {
          std::fprintf(stderr, "%s: %s\n", in.file, w.status().to_string().c_str());
          return 1;
        }
        sc.world = std::move(w.value());
      }
      std::sort(t.begin(), t.end());
      sc.build_ms = t[t.size() / 2];
      sc.h = sc.world.lattice().cell_size;
      const double longest = std::max({ext.x, ext.y, ext.z});
      if (std::abs(sc.h - longest / cells) > 1e-9 * longest)
        rows.notes.push_back(sc.name + ": h = " + fmt("%.6g", sc.h) + " is not the longest side / cells");
      sc.dig_radius = 0.05 * glm::length(ext);
      scene_bench(sc, opt, dev, dev1);
    }
  }
  if (wanted("landscape")) {
    Scene sc;
    sc.name = "landscape";
    std::vector<double> t;
    for (int r = 0; r < (opt.quick ? 1 : 3); ++r) {
      auto t0 = Clock::now();
      ldc::Result<ldc::World> w = ldc::build_terrain(ldc::TerrainConfig{}, 0.2);
      t.push_back(seconds_since(t0) * 1e3);
      if (!w.ok()) {
        std::fprintf(stderr, "landscape: %s\n", w.status().to_string().c_str());
        return 1;
      }
      sc.world = std::move(w.value());
    }
    std::sort(t.begin(), t.end());
    sc.build_ms = t[t.size() / 2];
    sc.h = sc.world.lattice().cell_size;
    const ldc::WorldBox box = sc.world.solid_bounds().value();
    sc.lo = box.min;
    sc.hi = box.max;
    for (int i = 0; i < 8; ++i)
      sc.frame.push_back({i & 1 ? sc.hi.x : sc.lo.x, i & 2 ? sc.hi.y : sc.lo.y, i & 4 ? sc.hi.z : sc.lo.z});
    sc.up = glm::dvec3(0.0, 0.0, 1.0);
    sc.dig_radius = 1.0;
    scene_bench(sc, opt, dev, dev1);
  }
  print_tables(opt);
  std::printf("\nTotal bench_query run time: %.0f s; load average at the start %s, at the end %s.\n",
              seconds_since(t_start), load_start.c_str(), load_average().c_str());
  return 0;
}
