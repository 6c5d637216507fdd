#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Side-by-side benchmark of CMGeom's textured simplification against meshoptimizer peers.

Usage: run_textured_peers.py <build-dir> [--models a,b] [--ratios 0.1,0.05,0.02] [--size 256]
                             [--out FILE] [--cmgeom PATH] [--meshopt018 PATH] [--keep] [--repeat R]

For every model of <data>/textured (<data> = $CMGEOM_DATA_DIR, else <repo>/../shared/data) and
every ratio (default 10 %, 5 %, 2 %, and 1 % for inputs above 20k faces):
  ours       `cmgeom simplify IN -o OUT.obj --ratio R --json` (default options; --texture for an OBJ
             that names no texture; --repair only when a plain run fails with a non-manifold error)
  peers, each at ours' reached face count, wearing the original texture:
    meshopt018            Debian's meshoptimizer 0.18, meshopt_simplify on the buffer split at UV
                          seams (<build-dir>/bin/meshopt018_simplify)
    mo13-attr             meshoptimizer 1.3.0 (npm) simplifyWithAttributes, UV weight 1/sqrt(mean UV area)
    mo13-perm-protect     the same + Permissive, UV-seam vertices tagged Protect in vertex_lock
    mo13-permissive       the same + Permissive, nothing protected (peers/meshopt_simplify.mjs)
and for every output: image RMSE (`cmgeom compare IN OUT --json --size N`, each mesh wearing the
texture named by its own MTL) and Metro Hausdorff / RMS (`cmgeom error IN OUT --json`, fractions of
the input's bounding-box diagonal). Ours' atlas is checked here (UVs in [0,1]^2, negatively oriented
and zero-area UV triangles, overlapping UV triangles on a uniform grid).

Writes one Markdown section (stdout, or --out FILE written atomically); progress goes to stderr. A
tool failing on one case is reported in its cell and in the failure list, never dropped; the exit
code is 0 when the section was written (even with failed cases), 1 on a harness error, 2 on bad
usage. Standard library only. Simplifications run one at a time, R times each (--repeat, default 3;
their times are reported as "min / median" of the R runs, the outputs of the last run are measured);
measurements run two at a time (2-core machines), each with one worker thread.
"""
import argparse
import concurrent.futures
import datetime
import hashlib
import json
import math
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
PEERS_DIR = os.path.join(HERE, "peers")
NODE_SCRIPT = os.path.join(PEERS_DIR, "meshopt_simplify.mjs")
DEFAULT_RATIOS = [0.1, 0.05, 0.02]
EXTRA_RATIO_LARGE = 0.01      # added to the default ratios for inputs above LARGE_FACES faces
LARGE_FACES = 20000
TIMEOUT = 1800                # seconds per command
FACE_SLACK = (1.02, 4)        # ours' faces <= 1.02 * target + 4
PEER_FACTOR = 1.1             # H and RMS targets: <= 1.1 x the best peer
UV_AREA_EPS = 1e-12           # |signed UV area| at or below this: zero-area triangle
UV_OVERLAP_EPS = 1e-6         # interiors intersecting by more than this (UV units): overlap
IMAGE_EXTS = (".png", ".jpg", ".jpeg", ".bmp", ".tga")

PEERS = [
    # name, kind, node variant
    ("meshopt018", "cpp", None),
    ("mo13-attr", "node", "attr"),
    ("mo13-perm-protect", "node", "permissive-protected"),
    ("mo13-permissive", "node", "permissive"),
]


def log(msg):
    print(msg, file=sys.stderr, flush=True)


class Usage(Exception):
    pass


# ---- commands ------------------------------------------------------------------------------------

def run(cmd, env=None):
    """Runs cmd; returns (returncode, stdout, stderr, seconds). Never raises for the command's own
    failure (a missing program or a timeout is returned as a failure too)."""
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=TIMEOUT, env=env)
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return -1, "", "timed out after %d s" % TIMEOUT, time.monotonic() - t0
    except OSError as e:
        return -1, "", "cannot run %s: %s" % (cmd[0], e), time.monotonic() - t0


def last_json(stdout):
    """The JSON object printed by a tool: the whole stdout, else its last non-empty line."""
    text = stdout.strip()
    try:
        return json.loads(text)
    except ValueError:
        lines = [l for l in text.splitlines() if l.strip()]
        return json.loads(lines[-1]) if lines else None


def short(msg, n=70):
    msg = " ".join(msg.split())
    return msg if len(msg) <= n else msg[: n - 1] + "…"


def fail_text(rc, err):
    lines = [l for l in err.strip().splitlines() if l.strip()]
    return "exit %d: %s" % (rc, lines[-1] if lines else "(no message)")


# ---- OBJ reading (for the checks) ------------------------------------------------------------------

def read_obj(path):
    """Positions, UVs, triangles (fan-split) as (p0, p1, p2, t0, t1, t2, material), mtllib lines."""
    pos, uv, tris, mtllibs = [], [], [], []
    mat = ""
    with open(path, encoding="utf-8", errors="replace") as f:
        for n, line in enumerate(f, 1):
            s = line.strip()
            if not s or s[0] == "#":
                continue
            key, _, rest = s.partition(" ")
            rest = rest.strip()
            if key == "v":
                t = rest.split()
                pos.append((float(t[0]), float(t[1]), float(t[2])))
            elif key == "vt":
                t = rest.split()
                uv.append((float(t[0]), float(t[1]) if len(t) > 1 else 0.0))
            elif key == "f":
                cs = []
                for c in rest.split():
                    parts = c.split("/")

                    def idx(tok, count, what):
                        i = int(tok)
                        r = i - 1 if i > 0 else count + i
                        if i == 0 or not 0 <= r < count:
                            raise ValueError("%s:%d: %s index %d out of range" % (path, n, what, i))
                        return r
                    vi = idx(parts[0], len(pos), "vertex")
                    ti = idx(parts[1], len(uv), "texture coordinate") if len(parts) > 1 and parts[1] else -1
                    cs.append((vi, ti))
                for k in range(1, len(cs) - 1):
                    a, b, c = cs[0], cs[k], cs[k + 1]
                    tris.append((a[0], b[0], c[0], a[1], b[1], c[1], mat))
            elif key == "usemtl":
                mat = rest
            elif key == "mtllib":
                mtllibs.append(rest)
    return pos, uv, tris, mtllibs


def mtl_paths(obj_path, mtllibs):
    """mtllib names resolved as CMGeom's reader does (whole rest of the line, else each word)."""
    d = os.path.dirname(os.path.abspath(obj_path))
    out = []
    for raw in mtllibs:
        whole = raw.replace("\\", "/")
        names = [whole] if os.path.isfile(os.path.join(d, whole)) else whole.split()
        out += [os.path.normpath(os.path.join(d, n)) for n in names]
    return out


def diffuse_textures(obj_path):
    """(mtl files, map_Kd files, problems) of an OBJ; problems lists what cannot be found."""
    mtls = mtl_paths(obj_path, mtllib_lines(obj_path))
    maps, problems = [], []
    for m in mtls:
        if not os.path.isfile(m):
            problems.append("MTL %s missing" % m)
            continue
        with open(m, encoding="utf-8", errors="replace") as f:
            for line in f:
                t = line.strip()
                if t.startswith("map_Kd"):
                    name = t[len("map_Kd"):].strip()
                    # options such as -s 1 1 1 come before the file name; the file name may hold spaces
                    while name.startswith("-"):
                        parts = name.split(None, 2)
                        name = parts[2] if len(parts) > 2 else ""
                    p = name if os.path.isabs(name) else os.path.join(os.path.dirname(m), name)
                    if os.path.isfile(p):
                        maps.append(os.path.normpath(p))
                    else:
                        problems.append("texture %s missing" % p)
    return mtls, maps, problems


def mtllib_lines(path):
    libs = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("mtllib"):
                libs.append(line[len("mtllib"):].strip())
    return libs


def count_triangles(path):
    n = 0
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("f ") or line.startswith("f\t"):
                n += max(0, len(line.split()) - 3)
    return n


# ---- UV checks ---------------------------------------------------------------------------------------

def signed_area(a, b, c):
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))


def interiors_overlap(A, B, eps):
    """Separating-axis test of two non-degenerate triangles: True when their interiors intersect by
    more than eps along every edge normal (touching along an edge or at a vertex is no overlap)."""
    for T in (A, B):
        for k in range(3):
            p, q = T[k], T[(k + 1) % 3]
            nx, ny = q[1] - p[1], p[0] - q[0]
            ln = math.hypot(nx, ny)
            if ln == 0.0:
                continue
            nx, ny = nx / ln, ny / ln
            pa = [v[0] * nx + v[1] * ny for v in A]
            pb = [v[0] * nx + v[1] * ny for v in B]
            if max(pa) <= min(pb) + eps or max(pb) <= min(pa) + eps:
                return False
    return True


def uv_check(path):
    """Counts on the UV triangles of an OBJ: UVs (used by faces) outside [0,1]^2, negatively oriented
    and zero-area triangles (corner order of the face, counter-clockwise positive), and overlapping
    pairs per material (uniform grid, interiors only)."""
    _, uv, tris, _ = read_obj(path)
    r = {"triangles": len(tris), "uv_missing": 0, "uv_out": 0, "negative": 0, "zero": 0, "overlaps": 0}
    used = set()
    good = {}  # material -> list of triangles (tuples of 3 uv points)
    for t in tris:
        if min(t[3:6]) < 0:
            r["uv_missing"] += 1
            continue
        used.update(t[3:6])
        a, b, c = uv[t[3]], uv[t[4]], uv[t[5]]
        s = signed_area(a, b, c)
        if abs(s) <= UV_AREA_EPS or not math.isfinite(s):
            r["zero"] += 1
            continue
        if s < 0:
            r["negative"] += 1
        good.setdefault(t[6], []).append((a, b, c))
    r["uv_out"] = sum(1 for i in used if not (0.0 <= uv[i][0] <= 1.0 and 0.0 <= uv[i][1] <= 1.0))
    for T in good.values():
        r["overlaps"] += count_overlaps(T)
    return r


def count_overlaps(T):
    if len(T) < 2:
        return 0
    xs = [p[0] for t in T for p in t]
    ys = [p[1] for t in T for p in t]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    g = max(1, int(math.sqrt(len(T))))
    sx = g / max(x1 - x0, 1e-30)
    sy = g / max(y1 - y0, 1e-30)
    cells = {}
    boxes = []
    for i, t in enumerate(T):
        bx0, bx1 = min(p[0] for p in t), max(p[0] for p in t)
        by0, by1 = min(p[1] for p in t), max(p[1] for p in t)
        boxes.append((bx0, bx1, by0, by1))
        for cx in range(min(g - 1, int((bx0 - x0) * sx)), min(g - 1, int((bx1 - x0) * sx)) + 1):
            for cy in range(min(g - 1, int((by0 - y0) * sy)), min(g - 1, int((by1 - y0) * sy)) + 1):
                cells.setdefault((cx, cy), []).append(i)
    seen = set()
    n = 0
    for members in cells.values():
        for a in range(len(members)):
            i = members[a]
            for b in range(a + 1, len(members)):
                j = members[b]
                key = (i, j) if i < j else (j, i)
                if key in seen:
                    continue
                seen.add(key)
                bi, bj = boxes[i], boxes[j]
                if bi[1] <= bj[0] + UV_OVERLAP_EPS or bj[1] <= bi[0] + UV_OVERLAP_EPS or \
                   bi[3] <= bj[2] + UV_OVERLAP_EPS or bj[3] <= bi[2] + UV_OVERLAP_EPS:
                    continue
                if interiors_overlap(T[i], T[j], UV_OVERLAP_EPS):
                    n += 1
    return n


# ---- the benchmark -----------------------------------------------------------------------------------

def data_dir():
    env = os.environ.get("CMGEOM_DATA_DIR")
    base = env if env else os.path.normpath(os.path.join(REPO, "..", "shared", "data"))
    return os.path.join(base, "textured"), ("CMGEOM_DATA_DIR" if env else "<repo>/../shared/data")


def find_models(root):
    models = {}
    for name in sorted(os.listdir(root)):
        d = os.path.join(root, name)
        if not os.path.isdir(d):
            continue
        objs = sorted(f for f in os.listdir(d) if f.lower().endswith(".obj"))
        if len(objs) != 1:
            log("skipping %s: %d OBJ files in %s" % (name, len(objs), d))
            continue
        obj = os.path.join(d, objs[0])
        texture = None
        if not mtllib_lines(obj):  # no material library: the only image of the folder is its texture (spot)
            imgs = sorted(f for f in os.listdir(d) if f.lower().endswith(IMAGE_EXTS))
            if len(imgs) != 1:
                log("skipping %s: its OBJ names no texture and the folder holds %d images" % (name, len(imgs)))
                continue
            texture = os.path.join(d, imgs[0])
        models[name] = {"obj": obj, "texture": texture}
    return models


def node_status():
    """(usable, description) of the Node peers."""
    node = shutil.which("node")
    if not node:
        return False, "node not found on PATH"
    pkg = os.path.join(PEERS_DIR, "node_modules", "meshoptimizer", "package.json")
    if not os.path.isfile(pkg):
        return False, "meshoptimizer not installed in %s (npm install there)" % PEERS_DIR
    with open(pkg) as f:
        version = json.load(f).get("version")
    if version != "1.3.0":
        return False, "peers/node_modules holds meshoptimizer %s, not 1.3.0 (npm install there)" % version
    rc, out, _, _ = run([node, "--version"])
    return True, "Node %s, meshoptimizer %s (npm, WebAssembly)" % (out.strip() if rc == 0 else "?", version)


def machine():
    model = None
    rc, out, _, _ = run(["lscpu"])
    if rc == 0:
        for line in out.splitlines():
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
                break
    return model or platform.processor() or "unknown CPU", os.cpu_count() or 0


def fmt(x, spec):
    return "—" if x is None else format(x, spec)


def ratio_label(r):
    return ("%g" % (100 * r)) + " %"


def min_median(secs, spec):
    """ "min / median" of a list of seconds ("?" when empty)."""
    if not secs:
        return "?"
    return "%s / %s" % (format(min(secs), spec), format(statistics.median(secs), spec))


class Bench:
    def __init__(self, args):
        self.repeat = max(1, args.repeat)
        self.args = args
        self.cmgeom = args.cmgeom
        self.meshopt018 = args.meshopt018
        self.failures = []          # (model, ratio, tool, stage, message)
        self.repair_models = set()  # models that needed --repair
        self.versions = {}          # peer kind -> meshoptimizer version the program reported
        self.pool = concurrent.futures.ThreadPoolExecutor(max_workers=2)
        self.measure_env = dict(os.environ, LP_NUM_THREADS="1")

    def fail(self, case, tool, stage, msg):
        self.failures.append((case["model"], case["ratio"], tool, stage, msg))
        return "FAIL (%s)" % stage

    def repeat_seconds(self, cmd, first):
        """The seconds of the JSON report `first` of cmd's first run, then of self.repeat - 1 more
        runs of cmd (a run that fails or reports no seconds adds nothing)."""
        secs = [first.get("seconds")]
        for _ in range(self.repeat - 1):
            rc, so, _, _ = run(cmd)
            if rc == 0:
                try:
                    secs.append(last_json(so).get("seconds"))
                except (ValueError, AttributeError):
                    pass
        return [float(x) for x in secs if isinstance(x, (int, float))]

    # ours ---------------------------------------------------------------------------------------------
    def run_ours(self, case, model, out):
        base = [self.cmgeom, "simplify", model["obj"], "-o", out, "--ratio", "%g" % case["ratio"], "--json"]
        if model["texture"]:
            base += ["--texture", model["texture"]]
        repair = case["model"] in self.repair_models
        rc, so, se, _ = run(base + (["--repair"] if repair else []))
        if rc != 0 and not repair and re.search(r"non-manifold", se, re.I):
            self.repair_models.add(case["model"])
            repair = True
            rc, so, se, _ = run(base + ["--repair"])
        case["ours_repair"] = repair
        if rc != 0:
            return None, fail_text(rc, se)
        try:
            j = last_json(so)
            secs = self.repeat_seconds(base + (["--repair"] if repair else []), j)
            return {"faces": int(j["faces_out"]), "target": int(j["target_faces"]),
                    "stopped_by": j.get("stopped_by"), "seconds": secs}, None
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            return None, "unreadable JSON report (%s)" % e

    # peers --------------------------------------------------------------------------------------------
    def run_peer(self, kind, variant, model_obj, out, faces, mtl):
        if kind == "cpp":
            cmd = [self.meshopt018, model_obj, out, "--faces", str(faces)]
        else:
            cmd = [shutil.which("node") or "node", NODE_SCRIPT, model_obj, out, "--faces", str(faces), "--variant", variant]
        if mtl:
            cmd += ["--mtl", mtl]
        rc, so, se, _ = run(cmd)
        if rc != 0:
            return None, fail_text(rc, se)
        try:
            j = last_json(so)
            if j.get("meshoptimizer"):
                self.versions[kind] = j["meshoptimizer"]
            return {"faces": int(j["faces_out"]), "seconds": self.repeat_seconds(cmd, j)}, None
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            return None, "unreadable JSON report (%s)" % e

    # measurements -------------------------------------------------------------------------------------
    def measure(self, model, out):
        """(image rmse, H, RMS, problems) of one output; runs compare and error concurrently."""
        problems = []
        _, _, tex_problems = diffuse_textures(out)
        if tex_problems:
            problems.append("texture: " + "; ".join(tex_problems))
        cmp_cmd = [self.cmgeom, "--threads", "1", "compare", model["obj"], out, "--json", "--size", str(self.args.size)]
        if model["texture"]:
            cmp_cmd += ["--texture", model["texture"]]
        err_cmd = [self.cmgeom, "--threads", "1", "error", model["obj"], out, "--json"]
        f_cmp = self.pool.submit(run, cmp_cmd, self.measure_env)
        f_err = self.pool.submit(run, err_cmd, self.measure_env)
        img = h = rms = None
        rc, so, se, _ = f_cmp.result()
        if rc != 0:
            problems.append("compare " + fail_text(rc, se))
        else:
            try:
                img = float(last_json(so)["rmse"])
            except (ValueError, KeyError, TypeError, AttributeError) as e:
                problems.append("compare: unreadable JSON (%s)" % e)
        rc, so, se, _ = f_err.result()
        if rc != 0:
            problems.append("error " + fail_text(rc, se))
        else:
            try:
                j = last_json(so)
                h, rms = float(j["hausdorff"]), float(j["rms"])
            except (ValueError, KeyError, TypeError, AttributeError) as e:
                problems.append("error: unreadable JSON (%s)" % e)
        if tex_problems:
            img = None  # a mesh without its texture would be compared wearing the reference's
        return img, h, rms, problems

    def run_case(self, case, model, work, peers_enabled, ref_mtl):
        d = os.path.join(work, "%s_%g" % (case["model"], case["ratio"]))
        os.makedirs(d, exist_ok=True)
        res = {}
        ours, err = self.run_ours(case, model, os.path.join(d, "ours.obj"))
        if err:
            res["ours"] = {"error": self.fail(case, "ours", "simplify", err)}
            count = case["target"]
        else:
            res["ours"] = ours
            case["target"] = ours["target"]
            count = ours["faces"]
        case["count"] = count
        for name, kind, variant in PEERS:
            if not peers_enabled[name][0]:
                res[name] = {"na": True}
                continue
            out = os.path.join(d, name + ".obj")
            r, err = self.run_peer(kind, variant, model["obj"], out, count, ref_mtl)
            res[name] = r if r else {"error": self.fail(case, name, "simplify", err)}
        # measurements, two commands at a time
        for name in ["ours"] + [p[0] for p in PEERS]:
            r = res[name]
            if "faces" not in r:
                continue
            out = os.path.join(d, name + ".obj")
            img, h, rms, problems = self.measure(model, out)
            r.update(img=img, h=h, rms=rms)
            for p in problems:
                self.fail(case, name, "measure", p)
            r["measure_failed"] = bool(problems)
        if "faces" in res["ours"]:
            try:
                res["ours"]["uv"] = uv_check(os.path.join(d, "ours.obj"))
            except (OSError, ValueError, IndexError) as e:
                res["ours"]["uv"] = None
                self.fail(case, "ours", "uv check", str(e))
        case["res"] = res
        if not self.args.keep:
            shutil.rmtree(d, ignore_errors=True)


def cell_value(r, key, spec):
    if r.get("na"):
        return "n/a"
    if "error" in r:
        return r["error"]
    v = r.get(key)
    return "FAIL" if v is None else format(v, spec)


def peer_cell(r, count):
    if r.get("na"):
        return "n/a"
    if "error" in r:
        return r["error"]
    mark = "†" if r["faces"] > FACE_SLACK[0] * count + FACE_SLACK[1] else ""
    return "%d%s / %s / %s / %s" % (r["faces"], mark, fmt(r.get("img"), ".2f") if r.get("img") is not None else "FAIL",
                                    fmt(r.get("h"), ".4f") if r.get("h") is not None else "FAIL",
                                    fmt(r.get("rms"), ".5f") if r.get("rms") is not None else "FAIL")


def verdicts(case):
    """(faces ok, image, H, RMS) verdict cells and booleans for the summary."""
    res = case["res"]
    ours = res["ours"]
    peer_results = [(p[0], res[p[0]]) for p in PEERS if not res[p[0]].get("na") and "faces" in res[p[0]]]
    n_enabled = sum(1 for p in PEERS if not res[p[0]].get("na"))
    out = {}
    if "faces" in ours:
        bound = FACE_SLACK[0] * case["target"] + FACE_SLACK[1]
        ok = ours["faces"] <= bound
        out["faces"] = (ok, "%d %s" % (ours["faces"], "✓" if ok else "✗ (> %.0f)" % bound)
                        + (" stopped_by: %s" % ours["stopped_by"] if ours.get("stopped_by") else "")
                        + (" (--repair)" if case.get("ours_repair") else ""))
    else:
        out["faces"] = (False, ours["error"])
    bound = FACE_SLACK[0] * case["count"] + FACE_SLACK[1]
    for key in ("img", "h", "rms"):
        mine = ours.get(key)
        theirs = [(r[key], name) for name, r in peer_results if r.get(key) is not None]
        reached = [(v, name) for v, name in theirs if res[name]["faces"] <= bound]
        missing = n_enabled - len(theirs)
        note = " (%d of %d peers)" % (len(theirs), n_enabled) if missing else ""
        if not n_enabled:
            out[key] = (None, "n/a (no peer)")
            out[key + "_reached"] = None
            continue
        if mine is None:
            out[key] = (False, "no (ours: no value)")
            out[key + "_reached"] = False
            continue
        if not theirs:
            out[key] = (None, "n/a (every peer failed)")
            out[key + "_reached"] = None
            continue

        def meets(pool):
            if not pool:
                return None, None
            best, who = min(pool)
            if key == "img":
                return mine < best, who
            q = mine / best if best > 0 else (1.0 if mine == 0 else math.inf)
            return q <= PEER_FACTOR, who
        ok, who = meets(theirs)
        best = min(theirs)[0]
        dagger = "†" if res[who]["faces"] > bound else ""
        if key == "img":
            text = "%s (%.2f vs %.2f %s%s)" % ("yes" if ok else "no", mine, best, who, dagger)
        else:
            q = mine / best if best > 0 else (1.0 if mine == 0 else math.inf)
            text = "%s (%.2f, best %s%s)" % ("yes" if ok else "no", q, who, dagger)
        out[key] = (ok, text + note)
        out[key + "_reached"] = meets(reached)[0]
    return out


def write_report(bench, cases, models, peers_enabled, meta, seconds, uv_inputs):
    a = bench.args
    L = []
    L.append("## Textured simplification against meshoptimizer peers")
    L.append("")
    L.append("Generated by `benchmark/Textured_simplification/run_textured_peers.py` (wrapper "
             "`run_textured_peers.sh`) on %s UTC; machine: %s, `nproc` = %d; whole run %.0f s."
             % (meta["date"], meta["cpu"], meta["nproc"], seconds))
    L.append("")
    if meta.get("cmgeom_changed"):
        L.append("Note: %s was rebuilt during the run; every row used the copy taken at the start (the "
                 "build described below), not the new one." % a.cmgeom_original)
        L.append("")
    L.append("Tools and exactly how they were run (IN = the model's OBJ, N = ours' reached face count; "
             "every peer keeps the original UVs of the vertices it keeps and wears the original texture "
             "through an MTL named by absolute path):")
    L.append("")
    L.append("- **ours**: %s, `cmgeom simplify IN -o OUT.obj --ratio R --json` with default options "
             "(new atlas and texture), `--texture FILE` for an OBJ that names no texture, `--repair` only "
             "where a plain run failed with a non-manifold error (%s)."
             % (meta["cmgeom_version"], ", ".join(sorted(bench.repair_models)) or "none"))
    deb = meta.get("deb_meshopt")
    L.append("- **meshopt018**: Debian's meshoptimizer %s%s, `meshopt018_simplify IN OUT.obj --faces N`: "
             "`meshopt_simplify(…, 3N, 1e30f, 0, &err)` on the vertex buffer split at UV seams (one vertex "
             "per distinct (position, uv)), so seams are attribute discontinuities it keeps. %s"
             % (bench.versions.get("cpp", "0.18"), " (package libmeshoptimizer-dev %s)" % deb if deb else "",
                "" if peers_enabled["meshopt018"][0] else "**Not run: %s.**" % peers_enabled["meshopt018"][1]))
    node_note = "" if peers_enabled["mo13-attr"][0] else " **Not run (columns n/a): %s.**" % peers_enabled["mo13-attr"][1]
    L.append("- **mo13-\\***: %s, `node peers/meshopt_simplify.mjs IN OUT.obj --faces N --variant V`: "
             "`MeshoptSimplifier.simplifyWithAttributes` on the same split buffer, UV as two attributes "
             "of weight 1/sqrt(mean \\|UV triangle area\\|) each, target 3N indices, target error 1e30, "
             "no LockBorder, no Prune. **mo13-attr**: no flag; **mo13-perm-protect**: `Permissive`, every "
             "vertex whose position is shared by several (position, uv) vertices tagged "
             "`meshopt_SimplifyVertex_Protect` (2) in `vertex_lock`; **mo13-permissive**: `Permissive`, "
             "nothing protected (collapses may cross UV seams).%s" % (peers_enabled["mo13-attr"][1] if peers_enabled["mo13-attr"][0] else "Node", node_note))
    L.append("- measurements: image RMSE (8-bit units, 26 views of %d×%d) `cmgeom --threads 1 compare IN OUT "
             "--json --size %d` (`--texture FILE` for the reference when its OBJ names none), each mesh "
             "wearing the texture its own MTL names; H and RMS: `cmgeom --threads 1 error IN OUT --json`, "
             "`hausdorff` and `rms`, fractions of the input's bounding-box diagonal." % (a.size, a.size, a.size))
    L.append("")
    L.append("Columns: target = ours' `target_faces`; ours' faces ✓ when ≤ %.2f×target+%d; each peer cell is "
             "*faces / image RMSE / H / RMS* at N faces (**†**: the peer stopped above N, compared anyway); "
             "\"image < every peer\" compares ours' image RMSE with the best peer's (named); the H and RMS columns "
             "give ours ÷ best peer, the target being ≤ %.1f; a peer that failed or was not run does not count "
             "(\"k of 4 peers\" says so). FAIL cells are explained in the failure list below."
             % (FACE_SLACK[0], FACE_SLACK[1], PEER_FACTOR))
    L.append("")
    head = ["model", "ratio", "target", "ours faces", "ours image", "ours H", "ours RMS"] + \
           [p[0] for p in PEERS] + ["image < every peer", "H ≤ 1.1× best peer", "RMS ≤ 1.1× best peer"]
    L.append("| " + " | ".join(head) + " |")
    L.append("|" + "|".join(["---"] * 2 + ["--:"] * 5 + ["--:"] * len(PEERS) + ["---"] * 3) + "|")
    tally = {"faces": 0, "img": 0, "h": 0, "rms": 0, "img_reached": 0, "h_reached": 0, "rms_reached": 0}
    for c in cases:
        v = verdicts(c)
        for k in ("faces", "img", "h", "rms"):
            tally[k] += 1 if v[k][0] else 0
        for k in ("img_reached", "h_reached", "rms_reached"):
            tally[k] += 1 if v.get(k) else 0
        o = c["res"]["ours"]
        row = ["%s (%d)" % (c["model"], c["faces_in"]), ratio_label(c["ratio"]), str(c["target"]),
               v["faces"][1], cell_value(o, "img", ".2f"), cell_value(o, "h", ".4f"), cell_value(o, "rms", ".5f")]
        row += [peer_cell(c["res"][p[0]], c["count"]) for p in PEERS]
        row += [v["img"][1], v["h"][1], v["rms"][1]]
        L.append("| " + " | ".join(row) + " |")
    n = len(cases)
    L.append("")
    L.append("**Summary** (%d cases): ours within the face budget %d/%d; image RMSE below every peer %d/%d; "
             "H ≤ %.1f× best peer %d/%d; RMS ≤ %.1f× best peer %d/%d."
             % (n, tally["faces"], n, tally["img"], n, PEER_FACTOR, tally["h"], n, PEER_FACTOR, tally["rms"], n))
    L.append("")
    L.append("The same against the peers that reached N (within %.2f×N+%d faces; the † peers left out): image "
             "RMSE below every peer %d/%d; H ≤ %.1f× best peer %d/%d; RMS ≤ %.1f× best peer %d/%d (a case where "
             "no peer reached N counts as not met)."
             % (FACE_SLACK[0], FACE_SLACK[1], tally["img_reached"], n, PEER_FACTOR, tally["h_reached"], n,
                PEER_FACTOR, tally["rms_reached"], n))
    L.append("")
    # timings
    L.append("Simplification seconds, \"min / median\" of %d runs (as each tool reports it: ours the whole "
             "`cmgeom simplify` work including the new texture, the peers the simplification call alone; IO "
             "excluded):" % bench.repeat)
    L.append("")
    L.append("| model | ratio | ours | " + " | ".join(p[0] for p in PEERS) + " |")
    L.append("|---|---|--:|" + "--:|" * len(PEERS))
    for c in cases:
        cells = []
        for name in ["ours"] + [p[0] for p in PEERS]:
            r = c["res"][name]
            cells.append("n/a" if r.get("na") else ("FAIL" if "error" in r else min_median(r.get("seconds"), ".3f")))
        L.append("| %s | %s | %s |" % (c["model"], ratio_label(c["ratio"]), " | ".join(cells)))
    L.append("")
    # UV checks
    L.append("Ours' output atlas, checked on the OBJ: UVs (used by faces) outside [0,1]²; UV triangles "
             "negatively oriented (signed area < 0, corners in face order, counter-clockwise positive) and "
             "zero-area (|area| ≤ %g); pairs of UV triangles of one material whose interiors overlap by more "
             "than %g UV units (uniform grid, separating-axis test; shared edges and vertices are no "
             "overlap). The input's counts are given for reference (mirrored or overlapping charts of the "
             "input show there)." % (UV_AREA_EPS, UV_OVERLAP_EPS))
    L.append("")
    L.append("| model | ratio | faces | UVs outside [0,1]² | negative | zero-area | overlapping pairs |")
    L.append("|---|---|--:|--:|--:|--:|--:|")
    uv_tally = {"uv_out": 0, "negative": 0, "zero": 0, "overlaps": 0}
    n_uv = 0
    shown_inputs = set()
    for c in cases:
        if c["model"] not in shown_inputs:
            shown_inputs.add(c["model"])
            u = uv_inputs.get(c["model"])
            if u:
                L.append("| %s | input | %d | %d | %d | %d | %d |" % (c["model"], u["triangles"], u["uv_out"],
                                                                    u["negative"], u["zero"], u["overlaps"]))
            else:
                L.append("| %s | input | FAIL | | | | |" % c["model"])
        o = c["res"]["ours"]
        u = o.get("uv") if "faces" in o else None
        if u is None:
            L.append("| %s | %s | FAIL | | | | |" % (c["model"], ratio_label(c["ratio"])))
            continue
        n_uv += 1
        for k in uv_tally:
            uv_tally[k] += 1 if u[k] == 0 else 0
        extra = " (+%d without UVs)" % u["uv_missing"] if u["uv_missing"] else ""
        L.append("| %s | %s | %d%s | %d | %d | %d | %d |" % (c["model"], ratio_label(c["ratio"]), u["triangles"], extra,
                                                          u["uv_out"], u["negative"], u["zero"], u["overlaps"]))
    L.append("")
    L.append("**UV summary** (%d outputs of ours checked, of %d cases): all UVs in [0,1]² %d; no negatively "
             "oriented triangle %d; no zero-area triangle %d; no overlapping pair %d."
             % (n_uv, n, uv_tally["uv_out"], uv_tally["negative"], uv_tally["zero"], uv_tally["overlaps"]))
    L.append("")
    L.append("Failures (%d):" % len(bench.failures))
    L.append("")
    if bench.failures:
        for m, r, tool, stage, msg in bench.failures:
            L.append("- %s %s, %s, %s: %s" % (m, ratio_label(r), tool, stage, short(msg, 300)))
    else:
        L.append("- none")
    L.append("")
    return "\n".join(L)


def parse_args(argv):
    p = argparse.ArgumentParser(prog="run_textured_peers.py", description=__doc__.split("\n\n")[0])
    p.add_argument("build_dir")
    p.add_argument("--models", help="comma-separated model names (folders of <data>/textured)")
    p.add_argument("--ratios", help="comma-separated fractions in (0,1] (default 0.1,0.05,0.02 and 0.01 above %d faces)" % LARGE_FACES)
    p.add_argument("--size", type=int, default=256, help="render size of cmgeom compare (default 256)")
    p.add_argument("--out", help="write the Markdown section to this file (default: stdout)")
    p.add_argument("--cmgeom", help="cmgeom binary (default <build-dir>/bin/cmgeom)")
    p.add_argument("--meshopt018", help="meshopt018_simplify binary (default <build-dir>/bin/meshopt018_simplify)")
    p.add_argument("--repeat", type=int, default=3, help="runs of every simplification (default 3)")
    p.add_argument("--keep", action="store_true", help="keep the work directory (its path goes to stderr)")
    a = p.parse_args(argv)
    a.cmgeom = os.path.abspath(a.cmgeom or os.path.join(a.build_dir, "bin", "cmgeom"))
    a.meshopt018 = os.path.abspath(a.meshopt018 or os.path.join(a.build_dir, "bin", "meshopt018_simplify"))
    if a.ratios:
        try:
            a.ratio_list = [float(x) for x in a.ratios.split(",") if x.strip()]
        except ValueError:
            raise Usage("--ratios: not a list of numbers: %s" % a.ratios)
        if not a.ratio_list or any(not 0 < r <= 1 for r in a.ratio_list):
            raise Usage("--ratios: fractions must lie in (0, 1]: %s" % a.ratios)
    else:
        a.ratio_list = None
    if not 16 <= a.size <= 4096:
        raise Usage("--size must lie in [16, 4096]")
    return a


def stamp(path):
    st = os.stat(path)
    return (st.st_mtime_ns, st.st_size)


def main(argv):
    try:
        a = parse_args(argv)
    except Usage as e:
        log("run_textured_peers.py: error: %s" % e)
        return 2
    if not (os.path.isfile(a.cmgeom) and os.access(a.cmgeom, os.X_OK)):
        log("run_textured_peers.py: error: no cmgeom at %s (build it: cmake --build <build-dir> --target cmgeom)" % a.cmgeom)
        return 1
    root, origin = data_dir()
    if not os.path.isdir(root):
        log("run_textured_peers.py: skipped: no textured models at %s (from %s; set CMGEOM_DATA_DIR)" % (root, origin))
        return 0
    models = find_models(root)
    if a.models:
        wanted = [m.strip() for m in a.models.split(",") if m.strip()]
        unknown = [m for m in wanted if m not in models]
        if unknown:
            log("run_textured_peers.py: error: unknown model(s) %s; known: %s" % (", ".join(unknown), ", ".join(models)))
            return 2
        models = {m: models[m] for m in wanted}
    if not models:
        log("run_textured_peers.py: skipped: no usable model in %s" % root)
        return 0

    node_ok, node_desc = node_status()
    m018_ok = os.path.isfile(a.meshopt018) and os.access(a.meshopt018, os.X_OK)
    m018_desc = "meshopt018_simplify not built at %s (cmake --build <build-dir> --target meshopt018_simplify, " \
                "benchmarks configured)" % a.meshopt018 if not m018_ok else a.meshopt018
    peers_enabled = {"meshopt018": (m018_ok, m018_desc)}
    for name, kind, _ in PEERS:
        if kind == "node":
            peers_enabled[name] = (node_ok, node_desc)
    for name, (ok, desc) in peers_enabled.items():
        if not ok:
            log("run_textured_peers.py: %s column n/a: %s" % (name, desc))

    cpu, nproc = machine()
    rc_deb, deb, _, _ = run(["dpkg-query", "-W", "-f=${Version}", "libmeshoptimizer-dev"])
    work = tempfile.mkdtemp(prefix="cmgeom-peers-")
    # Every command runs a snapshot of cmgeom taken now, so a rebuild of the build dir during the
    # run cannot mix two builds or catch a half-written binary (cmgeom needs only system libraries).
    snapshot = os.path.join(work, "cmgeom")
    for attempt in range(6):
        before = stamp(a.cmgeom)
        shutil.copy2(a.cmgeom, snapshot)
        rc, so, se, _ = run([snapshot, "--version"])
        if rc == 0 and stamp(a.cmgeom) == before:
            break
        time.sleep(10)
    else:
        shutil.rmtree(work, ignore_errors=True)
        log("run_textured_peers.py: error: no stable, runnable copy of %s (%s)" % (a.cmgeom, fail_text(rc, se)))
        return 1
    with open(snapshot, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()[:12]
    meta = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "cpu": cpu, "nproc": nproc, "deb_meshopt": deb.strip() if rc_deb == 0 else None,
            "cmgeom_version": "%s (%s built %s, sha256 %s…)" % (
                so.strip(), a.cmgeom,
                datetime.datetime.fromtimestamp(before[0] / 1e9, datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                digest)}
    a.cmgeom_original = a.cmgeom
    a.cmgeom = snapshot
    bench = Bench(a)
    t0 = time.monotonic()
    cases = []
    uv_inputs = {}
    try:
        for name, model in models.items():
            faces_in = count_triangles(model["obj"])
            ref_mtl = None
            if model["texture"]:
                # an MTL naming the original texture, so the peers' outputs wear it
                ref_mtl = os.path.join(work, name + "_reference.mtl")
                with open(ref_mtl, "w") as f:
                    f.write("newmtl %s\nKd 1 1 1\nmap_Kd %s\n" % (name, os.path.abspath(model["texture"])))
            try:
                uv_inputs[name] = uv_check(model["obj"])
            except (OSError, ValueError, IndexError) as e:
                log("run_textured_peers.py: %s: input UV check failed: %s" % (name, e))
            ratios = a.ratio_list or (DEFAULT_RATIOS + ([EXTRA_RATIO_LARGE] if faces_in > LARGE_FACES else []))
            for r in ratios:
                case = {"model": name, "ratio": r, "faces_in": faces_in, "target": max(1, int(round(r * faces_in)))}
                log("[%6.0f s] %s at %s" % (time.monotonic() - t0, name, ratio_label(r)))
                bench.run_case(case, model, work, peers_enabled, ref_mtl)
                cases.append(case)
        seconds = time.monotonic() - t0
        try:
            meta["cmgeom_changed"] = stamp(a.cmgeom_original) != before
        except OSError:
            meta["cmgeom_changed"] = True
        if meta["cmgeom_changed"]:
            log("run_textured_peers.py: note: %s changed during the run; the run used the copy taken at its "
                "start throughout" % a.cmgeom_original)
        text = write_report(bench, cases, models, peers_enabled, meta, seconds, uv_inputs)
    finally:
        bench.pool.shutdown(wait=True)
        if a.keep:
            log("work directory kept: %s" % work)
        else:
            shutil.rmtree(work, ignore_errors=True)
    if a.out:
        tmp = a.out + ".tmp-%d" % os.getpid()
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, a.out)
        log("wrote %s (%d cases, %d failures, %.0f s)" % (a.out, len(cases), len(bench.failures), seconds))
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
