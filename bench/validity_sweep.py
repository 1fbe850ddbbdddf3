#!/usr/bin/env python3
"""Validity sweep: random inputs through the `ldc` tool, every output checked by CGAL.

Usage: python3 bench/validity_sweep.py KIND [--seed S] [--runs N] [--ldc PATH] [--check PATH] [--work DIR]
                                            [--extra "ARGS"] (added to every command that makes a mesh)
  KIND   boolean | csg | remesh | edit
  boolean  two meshes of tests/data (and ../shared/meshes/suzanne.obj when present), B scaled
           to 0.3-1x A's size and moved by up to 0.3 of it; random op, cells 48-256, and one of:
           defaults, --max-error 0, 0.05 or 0.5, --chunk 16 or 64, --method mc
  csg      boxes and cylinders (6, 16 or 48 sides), axis-aligned or rotated, placed at random,
           on coplanar offsets, identical, or shifted by 1e-9 .. 1e-3; cells 32-256
  remesh   the meshes above at 40-300 cells: defaults, uniform, --max-error 0.05 or 1,
           --target-triangles 2000, --chunk 16
  edit     a 16 x 16 m landscape, 1-12 random brushes (ldc edit --validate), then ldc contour:
           uniform, --max-error 0.2 or 0.5, --method mc, --lod 1

Each output goes to cgal_check_mesh (tests/cgal/cgal_check_mesh.cpp: CGAL's is_valid_polygon_mesh,
is_closed, does_self_intersect); an empty result (disjoint shapes intersected) counts as valid.
Prints each invalid case (its inputs are kept in the work folder), each case whose level mesh fell back
to one level (ldc --json's surface_levels.fell_back: contour_levels left it non-manifold), and
"invalid: n of N" last.
Needs python3 (standard library only) and a build with CGAL (build/tests/cgal_check_mesh).
Bench only: not run by the tests or CI. Used for issue 19 (docs/contour.md).
"""
import argparse
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def mesh_files():
    data = os.path.join(ROOT, "tests", "data")
    files = [os.path.join(data, m) for m in ("stanford-bunny.obj", "fandisk.obj", "rocker-arm.obj", "spot.obj")]
    suzanne = os.path.join(ROOT, "..", "shared", "meshes", "suzanne.obj")
    return files + ([suzanne] if os.path.exists(suzanne) else [])


def bounds(path):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, v)]
                hi = [max(a, b) for a, b in zip(hi, v)]
    return lo, hi


def rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
    ry = [[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]
    rz = [[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]
    mul = lambda a, b: [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return mul(rz, mul(ry, rx))


def box(sx, sy, sz):
    v = [(x * sx / 2, y * sy / 2, z * sz / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    f = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, f


def cylinder(r, h, n):
    v = [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), s * h / 2)
         for s in (-1, 1) for i in range(n)] + [(0, 0, -h / 2), (0, 0, h / 2)]
    f = []
    for i in range(n):
        j = (i + 1) % n
        f += [(i, j, n + j), (i, n + j, n + i), (2 * n, j, i), (2 * n + 1, n + i, n + j)]
    return v, f


def write_obj(path, mesh, r, t):
    v, f = mesh
    with open(path, "w") as out:
        for p in v:
            out.write("v %.17g %.17g %.17g\n" % tuple(sum(r[i][k] * p[k] for k in range(3)) + t[i] for i in range(3)))
        for a, b, c in f:
            out.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


class Sweep:
    def __init__(self, args):
        self.ldc, self.check, self.work = args.ldc, args.check, args.work
        self.extra = args.extra.split()
        self.invalid = 0
        self.fell_back = 0

    def run(self, cmd):
        return subprocess.run(cmd, capture_output=True, text=True)

    def run_ldc(self, cmd, case):
        """Runs an ldc command with --json; counts (and prints) a level mesh that fell back to one level."""
        r = self.run(cmd + self.extra + ["--json"])
        if r.returncode == 0:
            try:
                levels = json.loads(r.stdout).get("surface_levels", {})
            except ValueError:
                levels = {}
            if levels.get("fell_back"):
                self.fell_back += 1
                print("FELL-BACK", " ".join(str(x) for x in case), flush=True)
        return r

    def judge(self, case, out, keep=()):
        c = self.run([self.check, out])
        text = (c.stdout + c.stderr).strip()
        if c.returncode == 0 or "no triangles" in text:
            return
        self.invalid += 1
        kept = []
        for path in keep:
            target = os.path.join(self.work, "case%d_%s" % (case[0], os.path.basename(path)))
            shutil.copy(path, target)
            kept.append(target)
        print("INVALID", " ".join(str(x) for x in case), "|", text[:300], "| kept:", " ".join(kept), flush=True)

    def boolean(self, i, rng, meshes, box_of):
        a, b = rng.choice(meshes), rng.choice(meshes)
        (la, ha), (lb, hb) = box_of[a], box_of[b]
        sa, sb = max(h - l for l, h in zip(la, ha)), max(h - l for l, h in zip(lb, hb))
        scale = sa / sb * rng.uniform(0.3, 1.0)
        t = [(la[k] + ha[k]) / 2 - (lb[k] + hb[k]) / 2 * scale + rng.uniform(-0.3, 0.3) * sa for k in range(3)]
        op = rng.choice(["union", "subtract", "intersect"])
        cells = rng.choice([48, 64, 97, 128, 160, 200, 256])
        extra = rng.choice([[], [], ["--max-error", "0"], ["--max-error", "0.05"], ["--max-error", "0.5"],
                            ["--chunk", "16"], ["--chunk", "64"], ["--method", "mc"]])
        out = os.path.join(self.work, "out.obj")
        cmd = [self.ldc, "--threads", "2", "-q", "boolean", a, b, "--op", op, "--cells", str(cells), "--scale-b",
               repr(scale), "--translate-b", ",".join(repr(x) for x in t), "-o", out] + extra
        r = self.run_ldc(cmd, (i, " ".join(cmd[4:])))
        if r.returncode != 0:
            print("LDC-ERROR", i, " ".join(cmd[4:]), r.stderr.strip()[-200:], flush=True)
            return
        self.judge((i, " ".join(cmd[4:])), out)

    def csg(self, i, rng):
        def shape():
            m = box(*(rng.uniform(0.3, 1.5) for _ in range(3))) if rng.random() < 0.67 else \
                cylinder(rng.uniform(0.2, 0.7), rng.uniform(0.3, 1.5), rng.choice([6, 16, 48]))
            r = rotation(*(rng.uniform(0, 6.3) for _ in range(3))) if rng.random() < 0.67 else rotation(0, 0, 0)
            return m, r
        (ma, ra), (mb, rb) = shape(), shape()
        placement = rng.choice(["random", "coplanar", "identical", "shifted"])
        if placement == "identical":
            mb, rb, tb = ma, ra, (0, 0, 0)
        elif placement == "shifted":
            mb, rb, tb = ma, ra, tuple(rng.choice([1e-9, 1e-6, 1e-3, 0]) for _ in range(3))
        elif placement == "coplanar":
            mb, rb, tb = ma, ra, tuple(rng.choice([0, 0.5, -0.5, 0.25]) for _ in range(3))
        else:
            tb = tuple(rng.uniform(-0.5, 0.5) for _ in range(3))
        fa, fb = os.path.join(self.work, "A.obj"), os.path.join(self.work, "B.obj")
        write_obj(fa, ma, ra, (0, 0, 0))
        write_obj(fb, mb, rb, tb)
        op = rng.choice(["union", "subtract", "intersect"])
        cells = rng.choice([32, 50, 64, 128, 256])
        extra = rng.choice([[], [], ["--max-error", "0"], ["--chunk", "16"]])
        out = os.path.join(self.work, "out.obj")
        r = self.run_ldc([self.ldc, "--threads", "2", "-q", "boolean", fa, fb, "--op", op, "--cells", str(cells),
                          "-o", out] + extra, (i, placement, op, cells))
        if r.returncode != 0:
            print("LDC-ERROR", i, placement, op, cells, extra, r.stderr.strip()[-200:], flush=True)
            return
        self.judge((i, placement, op, cells, " ".join(extra)), out, keep=(fa, fb))

    def remesh(self, i, rng, meshes):
        a = rng.choice(meshes)
        cells = rng.choice([40, 64, 100, 128, 180, 256, 300])
        extra = rng.choice([[], [], ["--max-error", "0"], ["--max-error", "0.05"], ["--max-error", "1"],
                            ["--target-triangles", "2000"], ["--chunk", "16"]])
        out = os.path.join(self.work, "out.obj")
        r = self.run_ldc([self.ldc, "--threads", "2", "-q", "remesh", a, "--cells", str(cells), "-o", out] + extra,
                         (i, "remesh", a, cells))
        if r.returncode != 0:
            print("LDC-ERROR", i, a, cells, extra, r.stderr.strip()[-200:], flush=True)
            return
        self.judge((i, "remesh", a, cells, " ".join(extra)), out)

    def edit(self, i, rng, world):
        edits = []
        for k in range(rng.randint(1, 12)):
            op = rng.choice(["subtract", "subtract", "union", "paint", "intersect"]) if k else rng.choice(["subtract", "union"])
            if op == "intersect" and rng.random() < 0.7:
                op = "subtract"
            c = [rng.uniform(0, 16), rng.uniform(0, 16), rng.uniform(2, 10)]
            kind = rng.choice(["sphere", "box", "capsule", "cylinder", "noise"])
            e = {"op": op, "brush": kind, "material": rng.randint(0, 3)}
            if kind in ("sphere", "noise"):
                e.update(centre=c, radius=rng.uniform(0.1, 4))
                if kind == "noise":
                    e.update(amplitude=rng.uniform(0.05, 0.5), frequency=rng.uniform(0.5, 4), seed=rng.randint(1, 99))
            elif kind == "box":
                e.update(centre=c, half_extents=[rng.uniform(0.05, 3) for _ in range(3)], rotate_deg=rng.uniform(0, 90),
                         axis=[rng.uniform(-1, 1) for _ in range(3)])
            else:
                e.update(a=c, b=[x + rng.uniform(-4, 4) for x in c], radius=rng.uniform(0.05, 2))
            edits.append(e)
        script = os.path.join(self.work, "edits.json")
        with open(script, "w") as f:
            json.dump({"edits": edits}, f)
        edited = os.path.join(self.work, "edited.ldc")
        r = self.run([self.ldc, "--threads", "2", "-q", "edit", world, "--script", script, "-o", edited, "--validate"])
        if r.returncode != 0:
            print("LDC-ERROR", i, "edit", r.stderr.strip()[-200:], flush=True)
            return
        extra = rng.choice([["--max-error", "0.2"], ["--max-error", "0.2"], ["--max-error", "0.5"], [],
                            ["--method", "mc"], ["--lod", "1"]])
        out = os.path.join(self.work, "out.obj")
        r = self.run([self.ldc, "--threads", "2", "-q", "contour", edited, "-o", out] + extra + self.extra)
        if r.returncode != 0:
            print("LDC-ERROR", i, "contour", extra, r.stderr.strip()[-200:], flush=True)
            return
        self.judge((i, "edit+contour", " ".join(extra)), out, keep=(script,))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("kind", choices=["boolean", "csg", "remesh", "edit"])
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--runs", type=int, default=50)
    p.add_argument("--ldc", default=os.path.join(ROOT, "build", "tools", "ldc"))
    p.add_argument("--check", default=os.path.join(ROOT, "build", "tests", "cgal_check_mesh"))
    p.add_argument("--meshes", default=None,
                   help="comma-separated OBJ files to use instead of the built-in list (held-out inputs)")
    p.add_argument("--extra", default="",
                   help="more ldc arguments for every command that makes a mesh, e.g. '--slack 1'")
    p.add_argument("--work", default=None, help="folder for outputs and kept failing inputs (default: a new temporary one)")
    args = p.parse_args()
    for tool in (args.ldc, args.check):
        if not os.access(tool, os.X_OK):
            sys.exit("validity_sweep: no executable at %s (build first)" % tool)
    args.work = args.work or tempfile.mkdtemp(prefix="ldc-sweep-")
    os.makedirs(args.work, exist_ok=True)
    sweep, rng = Sweep(args), random.Random(args.seed)
    meshes = args.meshes.split(",") if args.meshes else mesh_files()
    box_of = {m: bounds(m) for m in meshes} if args.kind == "boolean" else {}
    world = os.path.join(args.work, "landscape.ldc")
    if args.kind == "edit":
        subprocess.run([args.ldc, "-q", "terrain", "--size", "16,16", "-o", world], check=True)
    for i in range(args.runs):
        if args.kind == "boolean":
            sweep.boolean(i, rng, meshes, box_of)
        elif args.kind == "csg":
            sweep.csg(i, rng)
        elif args.kind == "remesh":
            sweep.remesh(i, rng, meshes)
        else:
            sweep.edit(i, rng, world)
    print("work folder:", args.work)
    print("fell back to one level (a level mesh came out non-manifold): %d of %d" % (sweep.fell_back, args.runs))
    print("invalid: %d of %d" % (sweep.invalid, args.runs))


if __name__ == "__main__":
    main()
