#!/usr/bin/env python3
"""Blender round trip (docs/blender.md): the `follicle` CLI writes meshes and hair from shipped
scenes and meshes, Blender (headless) imports them with its own importers or the groom add-on in
tools/blender/, and exports meshes that `follicle info` reads back. Blender only measures
(blender_side.py); this driver compares its numbers with what `follicle info` prints.

usage: blender_interop.py --follicle EXE --source-dir DIR --work-dir DIR [--blender=EXE] TEST
TEST: import-obj | import-ply | import-gltf | import-hair-obj | export-mesh | groom-addon

Exit codes: 0 pass, 1 a mismatch or a failed command (every message names the file and the
numbers), 77 Blender is not installed (CTest SKIP_RETURN_CODE).

Bounds tolerance: 1e-5 of the larger of the reference bounding-box diagonal and its largest
coordinate magnitude (about 6 um on the 0.6 m head), far above float32 rounding (6e-8 relative),
`follicle info`'s 6 significant digits (5e-6 relative) and Blender's 6-decimal OBJ writer (0.5 um),
far below any real error (a missing vertex row, a unit slip, an axis flip). Strand lengths: 1e-5
relative. Counts are exact.
"""
import argparse
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import time

SKIP = 77
HERE = os.path.dirname(os.path.abspath(__file__))
REL_TOL = 1e-5


class Checker:
    def __init__(self):
        self.failures = []
        self.passed = 0

    def fail(self, msg):
        self.failures.append(msg)
        print("FAIL " + msg, flush=True)

    def ok(self, msg):
        self.passed += 1
        print("ok   " + msg, flush=True)

    def equal(self, what, blender, follicle, where):
        if blender == follicle:
            self.ok("%s: %s = %s" % (where, what, follicle))
        else:
            self.fail("%s: %s: Blender %s, follicle info %s" % (where, what, blender, follicle))

    def true(self, cond, msg):
        (self.ok if cond else self.fail)(msg)

    def bounds(self, got, want, where, note):
        """got/want: {"min": [3], "max": [3]} in the same unit."""
        if got is None:
            self.fail("%s: Blender has no vertices to bound (%s)" % (where, note))
            return
        diag = math.dist(want["min"], want["max"])
        mag = max(abs(v) for v in want["min"] + want["max"])
        tol = REL_TOL * max(diag, mag)
        err = max(abs(g - w) for k in ("min", "max") for g, w in zip(got[k], want[k]))
        fmt = lambda b: "min [%s] max [%s]" % (", ".join("%.7g" % v for v in b["min"]),
                                               ", ".join("%.7g" % v for v in b["max"]))
        if err <= tol:
            self.ok("%s: bounds agree within %.3g (tolerance %.3g; %s)" % (where, err, tol, note))
        else:
            self.fail("%s: bounds differ by %.6g > tolerance %.3g (%s): Blender %s, expected "
                      "from follicle info %s" % (where, err, tol, note, fmt(got), fmt(want)))

    def close(self, what, blender, follicle, where, rel=REL_TOL):
        tol = rel * max(abs(follicle), 1e-30)
        if abs(blender - follicle) <= tol:
            self.ok("%s: %s %.7g ~ %.7g" % (where, what, blender, follicle))
        else:
            self.fail("%s: %s: Blender %.9g, follicle info %.9g (relative tolerance %g)"
                      % (where, what, blender, follicle, rel))


# ------------------------------------------------------------------------------- follicle side

def run(cmd, what, timeout=300):
    t = time.time()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       timeout=timeout)
    if p.returncode != 0:
        raise RuntimeError("%s failed (exit %d): %s\n%s%s" % (what, p.returncode, " ".join(cmd),
                                                             p.stdout[-4000:], p.stderr[-4000:]))
    return p.stdout, time.time() - t


class Follicle:
    def __init__(self, exe, source):
        self.exe = exe
        self.source = source

    def __call__(self, *args):
        out, dt = run([self.exe, *args], "follicle " + args[0])
        shown = out.strip().replace("\n", "\n  ")
        print("follicle %s  (%.2f s)\n  %s" % (" ".join(args), dt, shown), flush=True)
        return out

    def data(self, rel):
        return os.path.join(self.source, rel)

    def info(self, path, units="m"):
        """`follicle info` parsed: counts, bounds {"min", "max"} and the printed unit."""
        out, _ = run([self.exe, "info", path, "--units", units], "follicle info " + path)
        d = {"file": os.path.basename(path)}
        num = r"(-?[0-9.]+(?:e[-+]?[0-9]+)?)"
        for key in ("vertices", "faces", "strands", "points", "segments"):
            m = re.search(r"^%s: (\d+)" % key, out, re.M)
            if m:
                d[key] = int(m.group(1))
        b = {}
        for key in ("min", "max"):
            m = re.search(r"^bounds %s: \[%s, %s, %s\] (\S+)" % (key, num, num, num), out, re.M)
            if m:
                b[key] = [float(m.group(i)) for i in (1, 2, 3)]
                d["unit"] = m.group(4)
        if b:
            d["bounds"] = b
        m = re.search(r"^points per strand: min (\d+), max (\d+)", out, re.M)
        if m:
            d["points_min"], d["points_max"] = int(m.group(1)), int(m.group(2))
        m = re.search(r"^strand length: min %s, mean %s, max %s" % (num, num, num), out, re.M)
        if m:
            d["length_min"], d["length_mean"], d["length_max"] = (float(m.group(i))
                                                                  for i in (1, 2, 3))
        m = re.search(r"^normals: (yes|no)", out, re.M)
        if m:
            d["normals"] = m.group(1) == "yes"
        m = re.search(r"^format: (\S+)", out, re.M)
        if m:
            d["format"] = m.group(1)
        return d


UNIT_M = {"mm": 1e-3, "cm": 1e-2, "dm": 1e-1, "m": 1.0}


def scaled(b, k):
    return {"min": [k * v for v in b["min"]], "max": [k * v for v in b["max"]]}


def yup_to_zup(b):
    """Bounds after Blender's Y-up -> Z-up import conversion (x, y, z) -> (x, -z, y)."""
    return {"min": [b["min"][0], -b["max"][2], b["min"][1]],
            "max": [b["max"][0], -b["min"][2], b["max"][1]]}


# -------------------------------------------------------------------------------- Blender side

def find_blender(arg):
    for cand in (os.environ.get("FOLLICLE_BLENDER"), arg, shutil.which("blender")):
        if cand and os.path.isfile(cand) and os.access(cand, os.X_OK):
            return cand
    return None


def run_blender(blender, work, job, name):
    job_path = os.path.join(work, name + ".job.json")
    job["result"] = os.path.join(work, name + ".result.json")
    with open(job_path, "w") as f:
        json.dump(job, f, indent=1)
    env = dict(os.environ)
    # Debian's Blender embeds the system Python and finds its home through the first python3.x
    # on PATH. When this driver runs under pyenv or a virtualenv, that interpreter's folder leads
    # PATH and Blender loses /usr/lib/python3/dist-packages (numpy): keep it out of Blender's PATH.
    here = os.path.realpath(os.path.dirname(sys.executable))
    if here not in ("/usr/bin", "/bin"):
        env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                      if p and os.path.realpath(p) != here)
    # Keep the user's Blender configuration out of the test (and the add-on install in scratch).
    env["BLENDER_USER_SCRIPTS"] = os.path.join(work, "blender_user", "scripts")
    env["BLENDER_USER_CONFIG"] = os.path.join(work, "blender_user", "config")
    cmd = [blender, "-b", "--factory-startup", "--python-exit-code", "1",
           "--python", os.path.join(HERE, "blender_side.py"), "--", job_path]
    t = time.time()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600, env=env, cwd=work)
    dt = time.time() - t
    log = os.path.join(work, name + ".blender.log")
    with open(log, "w") as f:
        f.write(p.stdout)
    if p.returncode != 0 or not os.path.exists(job["result"]):
        raise RuntimeError("Blender failed (exit %d) on %s; log %s:\n%s"
                           % (p.returncode, job_path, log, p.stdout[-6000:]))
    with open(job["result"]) as f:
        res = json.load(f)
    print("blender %s: %d steps in %.1f s (Blender %s; log %s)"
          % (name, len(job["steps"]), dt, res["blender_version"], log), flush=True)
    return res


def step_result(res, name):
    for s in res["steps"]:
        if s["name"] == name:
            return s
    raise KeyError(name)


def imported(c, s, where, kind="mesh_objects"):
    """True when the step imported; a failed or empty import is a failure naming the file."""
    if "import_error" in s:
        c.fail("%s: Blender import failed: %s" % (where, s["import_error"]))
        return False
    m = s["measure"]
    if m[kind] < 1:
        c.fail("%s: Blender imported no %s (objects: %s)" % (where, kind.replace("_", " "),
                                                             m["object_types"]))
        return False
    return True


def check_mesh(c, s, ref, where, expect_bounds, note):
    if not imported(c, s, where):
        return
    m = s["measure"]
    c.equal("vertices", m["vertices"], ref["vertices"], where)
    c.equal("faces (polygons)", m["polygons"], ref["faces"], where)
    c.equal("non-triangle polygons", m["non_triangles"], 0, where)
    c.bounds(m["bounds"], expect_bounds, where, note)


# ------------------------------------------------------------------------------------- tests

def make_meshes(f, work, fmts, units="m"):
    """head.EXT: the deformed, wrinkled face of skin_troubled.json (`follicle export --mesh`);
    sintel.EXT: the Sintel bust converted from centimetres (`follicle convert`). The head is
    centred (symmetric bounds), the bust is not, so the bust catches axis sign slips."""
    files = {}
    scene = f.data("data/scenes/skin_troubled.json")
    for ext in fmts:
        head = os.path.join(work, "head" + ext)
        f("export", scene, "--mesh", head, "--units", units)
        bust = os.path.join(work, "sintel" + ext)
        f("convert", f.data("data/meshes/sintel/sintel.obj"), bust, "--in-units", "cm",
          "--out-units", units)
        files[ext] = (head, bust)
    return files


def test_import_obj(c, f, blender, work):
    (head, bust), = make_meshes(f, work, [".obj"]).values()
    head_mm = os.path.join(work, "head_mm.obj")
    f("export", f.data("data/scenes/skin_troubled.json"), "--mesh", head_mm, "--units", "mm")
    # forward Y / up Z is Blender's own frame: the importer's axis conversion is switched off.
    same = {"forward_axis": "Y", "up_axis": "Z"}
    steps = [
        {"name": "head", "import": {"op": "wm.obj_import",
                                    "kwargs": dict(filepath=head, **same)}, "measure": "mesh"},
        {"name": "bust", "import": {"op": "wm.obj_import",
                                    "kwargs": dict(filepath=bust, **same)}, "measure": "mesh"},
        {"name": "bust_default_axes", "import": {"op": "wm.obj_import",
                                                 "kwargs": {"filepath": bust}}, "measure": "mesh"},
        {"name": "head_mm", "import": {"op": "wm.obj_import",
                                       "kwargs": dict(filepath=head_mm, global_scale=0.001,
                                                      **same)}, "measure": "mesh"},
    ]
    res = run_blender(blender, work, {"steps": steps}, "import_obj")
    rh, rb, rmm = f.info(head), f.info(bust), f.info(head_mm, "mm")
    note = "wm.obj_import forward Y, up Z: no axis conversion"
    check_mesh(c, step_result(res, "head"), rh, "head.obj", rh["bounds"], note)
    check_mesh(c, step_result(res, "bust"), rb, "sintel.obj", rb["bounds"], note)
    check_mesh(c, step_result(res, "bust_default_axes"), rb, "sintel.obj (default axes)",
               yup_to_zup(rb["bounds"]), "importer default forward -Z, up Y: (x, y, z) -> "
               "(x, -z, y)")
    check_mesh(c, step_result(res, "head_mm"), rmm, "head_mm.obj (mm)",
               scaled(rmm["bounds"], UNIT_M[rmm["unit"]]),
               "file in mm, global_scale 0.001, compared in metres")


def test_import_ply(c, f, blender, work):
    (head, bust), = make_meshes(f, work, [".ply"]).values()
    steps = [{"name": n, "import": {"op": "import_mesh.ply", "kwargs": {"filepath": p}},
              "measure": "mesh"} for n, p in (("head", head), ("bust", bust))]
    res = run_blender(blender, work, {"steps": steps}, "import_ply")
    note = "import_mesh.ply has no axis conversion"
    for n, p in (("head", head), ("bust", bust)):
        ref = f.info(p)
        check_mesh(c, step_result(res, n), ref, os.path.basename(p), ref["bounds"], note)


def test_import_gltf(c, f, blender, work):
    files = make_meshes(f, work, [".gltf", ".glb"])
    steps, refs = [], {}
    for ext, pair in files.items():
        for p in pair:
            n = os.path.basename(p)
            steps.append({"name": n, "import": {"op": "import_scene.gltf",
                                                "kwargs": {"filepath": p}}, "measure": "mesh"})
            refs[n] = f.info(p)
    res = run_blender(blender, work, {"steps": steps}, "import_gltf")
    for n, ref in refs.items():
        # glTF is Y-up metres by specification; import_scene.gltf always converts to Z-up and has
        # no option to keep the axes, so the expected bounds are swapped.
        check_mesh(c, step_result(res, n), ref, n, yup_to_zup(ref["bounds"]),
                   "glTF Y-up converted by the importer: (x, y, z) -> (x, -z, y)")


def check_hair_edges(c, s, ref, where, note):
    if not imported(c, s, where):
        return
    m = s["measure"]
    c.equal("vertices = points", m["vertices"], ref["points"], where)
    c.equal("edges = segments", m["edges"], ref["segments"], where)
    c.equal("connected components = strands", m["components"], ref["strands"], where)
    c.equal("points per strand min", m["component_min"], ref["points_min"], where)
    c.equal("points per strand max", m["component_max"], ref["points_max"], where)
    c.equal("branching vertices", m["branching_vertices"], 0, where)
    c.equal("faces", m["polygons"], 0, where)
    c.close("total strand length [m]", m["total_edge_length"],
            ref["length_mean"] * ref["strands"] * UNIT_M[ref["unit"]], where)
    c.bounds(m["bounds"], scaled(ref["bounds"], UNIT_M[ref["unit"]]), where, note)


def test_import_hair_obj(c, f, blender, work):
    hair = os.path.join(work, "bob_hair.obj")
    f("export", f.data("data/scenes/anjyo_bob.json"), "--hair", hair, "--units", "m")
    ref = f.info(hair)
    steps = [
        # Blender 3.4's Python OBJ importer (io_scene_obj) turns each `l` polyline into edges.
        {"name": "legacy", "import": {"op": "import_scene.obj", "kwargs": {
            "filepath": hair, "axis_forward": "Y", "axis_up": "Z", "use_edges": True,
            "use_split_objects": False, "use_split_groups": False}}, "measure": "edges"},
        # The C++ importer (File > Import > Wavefront (.obj) in 3.4).
        {"name": "new", "import": {"op": "wm.obj_import", "kwargs": {
            "filepath": hair, "forward_axis": "Y", "up_axis": "Z"}}, "measure": "edges"},
    ]
    res = run_blender(blender, work, {"steps": steps}, "import_hair_obj")
    note = "no axis conversion (forward Y, up Z)"
    legacy, new = step_result(res, "legacy"), step_result(res, "new")
    if "missing_operator" in legacy:  # Blender 4 dropped it: the C++ importer must read polylines
        print("NOTE Blender %s has no import_scene.obj; checking wm.obj_import strictly"
              % res["blender_version"])
        check_hair_edges(c, new, ref, "bob_hair.obj (wm.obj_import)", note)
        return
    check_hair_edges(c, legacy, ref, "bob_hair.obj (import_scene.obj)", note)
    m = new.get("measure", {})
    if m.get("vertices") == ref["points"] and m.get("edges") == ref["segments"]:
        check_hair_edges(c, new, ref, "bob_hair.obj (wm.obj_import)", note)
    else:
        # A Blender limitation, not a Follicle mismatch: reported, not failed (docs/blender.md).
        print("NOTE bob_hair.obj (wm.obj_import, Blender %s): %s vertices and %s edges for %d "
              "points, %d segments and %d `l` polylines: this importer keeps only the first "
              "segment of each polyline (a Blender limitation; import_scene.obj above reads them "
              "all)" % (res["blender_version"], m.get("vertices"), m.get("edges"), ref["points"],
                        ref["segments"], ref["strands"]), flush=True)


def ext_of(path):
    return os.path.splitext(path)[1].lower()


def test_export_mesh(c, f, blender, work):
    files = make_meshes(f, work, [".obj", ".ply", ".glb", ".gltf"])
    plans = {  # source ext: (importer, export op, export kwargs, export ext, axis note)
        ".obj": ("wm.obj_import", {}, "wm.obj_export",
                 {"export_selected_objects": True, "export_materials": False,
                  "export_uv": True, "export_normals": True},
                 "importer and exporter defaults: Y-up -> Z-up -> Y-up"),
        ".ply": ("import_mesh.ply", {}, "export_mesh.ply",
                 {"use_selection": True, "use_normals": True, "use_uv_coords": True,
                  "use_colors": False}, "PLY: no axis conversion either way"),
        ".glb": ("import_scene.gltf", {}, "export_scene.gltf",
                 {"export_format": "GLB", "use_selection": True, "export_materials": "NONE"},
                 "glTF: Y-up -> Z-up on import, export_yup back"),
        ".gltf": ("import_scene.gltf", {}, "export_scene.gltf",
                  {"export_format": "GLTF_SEPARATE", "use_selection": True,
                   "export_materials": "NONE"}, "glTF (+ .bin): Y-up -> Z-up -> Y-up"),
    }
    steps, jobs = [], []
    for ext, (imp, ikw, exp, ekw, note) in plans.items():
        for src in files[ext]:
            out = os.path.join(work, "blender_" + os.path.basename(src))
            if os.path.exists(out):
                os.remove(out)
            name = os.path.basename(src)
            steps.append({"name": name, "import": {"op": imp, "kwargs": dict(filepath=src, **ikw)},
                          "measure": "mesh",
                          "export": {"op": exp, "kwargs": dict(filepath=out, **ekw)}})
            jobs.append((name, src, out, note))
    res = run_blender(blender, work, {"steps": steps}, "export_mesh")
    for name, src, out, note in jobs:
        s = step_result(res, name)
        if not imported(c, s, name):
            continue
        if not os.path.exists(out):
            c.fail("%s: Blender wrote no %s (export result %s)" % (name, out,
                                                                    s.get("export_result")))
            continue
        where = "%s -> Blender -> %s" % (name, os.path.basename(out))
        try:
            got = f.info(out)
        except RuntimeError as e:
            c.fail("%s: follicle info cannot read Blender's file: %s" % (where, e))
            continue
        ref = f.info(src)
        want_v = ref["vertices"]
        if ext_of(src) in (".glb", ".gltf") and not ref.get("normals", True):
            # A glTF primitive without NORMAL is flat-shaded by specification (Blender would
            # write one vertex per corner); Follicle's meshes carry normals (the OBJ reader once
            # dropped the `vn` of data/meshes/sintel/sintel.obj).
            c.fail("%s: follicle info reports 'normals: no' for %s" % (where, name))
        for what, g, w in (("vertices", got["vertices"], want_v),
                           ("faces", got["faces"], ref["faces"])):
            if g == w:
                c.ok("%s: %s = %d" % (where, what, w))
            else:
                c.fail("%s: %s: follicle info on Blender's file %d, expected %d (follicle info on "
                       "the original %s: %d)" % (where, what, g, w, name, ref[what]))
        c.bounds(got["bounds"], ref["bounds"], where, note + "; both files read by follicle info")


def write_test_hair(path):
    """A .hair without a segments array (header default: 6 segments) but with thickness,
    transparency and colour arrays, none of which Follicle writes: 12 strands x 7 points, metres."""
    n_strands, n_seg = 12, 6
    pts, thick = [], []
    for h in range(n_strands):
        a = 0.5 * h
        for i in range(n_seg + 1):
            pts += [0.06 * math.cos(a) + 0.002 * i, 0.15 - (0.01 + 0.001 * h) * i,
                    0.06 * math.sin(a) + 0.0005 * i * i]
            thick.append(1e-4 * (1.0 - i / (2 * n_seg)))
    n = len(pts) // 3
    hdr = struct.pack("<4sIIIIff3f88s", b"HAIR", n_strands, n, 2 | 4 | 8 | 16, n_seg, 1.0, 0.0,
                      0.5, 0.5, 0.5, b"blender_interop.py test groom")
    body = struct.pack("<%df" % len(pts), *pts) + struct.pack("<%df" % n, *thick)
    body += struct.pack("<%df" % n, *([0.25] * n)) + struct.pack("<%df" % (3 * n), *([0.3] * 3 * n))
    with open(path, "wb") as fh:
        fh.write(hdr + body)
    return min(thick) / 2, max(thick) / 2


def check_groom(c, s, ref, where, expect_bounds, note, units):
    if not imported(c, s, where, "curve_objects"):
        return
    m = s["measure"]
    c.equal("curve objects", m["curve_objects"], 1, where)
    c.equal("splines = strands", m["splines"], ref["strands"], where)
    c.equal("points", m["points"], ref["points"], where)
    c.equal("points per strand min", m["points_min"], ref["points_min"], where)
    c.equal("points per strand max", m["points_max"], ref["points_max"], where)
    c.equal("spline types", m["spline_types"], ["POLY"], where)
    k = UNIT_M[ref["unit"]]
    for key in ("length_min", "length_mean", "length_max"):
        c.close("strand %s [m]" % key.split("_")[1], m[key], ref[key] * k, where)
    c.bounds(m["bounds"], expect_bounds, where, note)
    props = m["properties"]
    c.true(props.get("follicle_strands") == ref["strands"] and
           props.get("follicle_points") == ref["points"] and props.get("follicle_units") == units,
           "%s: object properties record the counts and unit: %s (follicle info: %d strands, "
           "%d points; units %s)" % (where, props, ref["strands"], ref["points"], units))


def test_groom_addon(c, f, blender, work):
    tfx = f.data("data/grooms/sintel/sintel_hair.tfx")
    sintel_hair = os.path.join(work, "sintel_from_tfx.hair")
    f("convert", tfx, sintel_hair, "--in-units", "cm", "--out-units", "cm")
    bob_hair = os.path.join(work, "bob.hair")
    f("export", f.data("data/scenes/anjyo_bob.json"), "--hair", bob_hair, "--units", "mm")
    test_hair = os.path.join(work, "thick_default_segments.hair")
    rmin, rmax = write_test_hair(test_hair)
    bad_hair = os.path.join(work, "truncated.hair")
    with open(bob_hair, "rb") as fh:
        data = fh.read()
    with open(bad_hair, "wb") as fh:
        fh.write(data[:len(data) - 6])
    addon = {"file": os.path.join(f.source, "tools", "blender", "follicle_grooms.py"),
             "module": "follicle_grooms"}
    cases = [  # name, operator, file, units (file and add-on), add-on axis
        ("sintel.tfx", "follicle_tfx", tfx, "cm", "Y_UP"),
        ("sintel_from_tfx.hair", "follicle_hair", sintel_hair, "cm", "Y_UP"),
        ("bob.hair", "follicle_hair", bob_hair, "mm", "Z_UP"),
        ("thick_default_segments.hair", "follicle_hair", test_hair, "m", "Z_UP"),
    ]
    steps = [{"name": n, "measure": "curves",
              "import": {"op": "import_curve." + op, "kwargs": {
                  "filepath": p, "units": u.upper(), "axis": ax}}}
             for n, op, p, u, ax in cases]
    steps.append({"name": "truncated.hair", "measure": "curves",
                  "import": {"op": "import_curve.follicle_hair", "kwargs": {"filepath": bad_hair}}})
    res = run_blender(blender, work, {"addon": addon, "steps": steps}, "groom_addon")

    a = res["addon"]
    c.true(a["install"] == ["FINISHED"] and a["enable"] == ["FINISHED"] and a["enabled"],
           "add-on installs and enables from %s (installed as %s)" % (addon["file"],
                                                                       a["module_file"]))
    c.true(a["bl_info_category"] == "Import-Export" and a["bl_info_name"],
           "bl_info: %r, category %r" % (a["bl_info_name"], a["bl_info_category"]))
    c.true(a["import_menu_entries"] == ["menu_func_hair", "menu_func_tfx"],
           "File > Import entries after enabling: %s" % a["import_menu_entries"])
    c.true(a["operators"] == ["follicle_hair", "follicle_tfx"],
           "operators import_curve.follicle_hair / follicle_tfx registered: %s" % a["operators"])
    c.true(not a["menu_entries_after_disable"] and not a["operators_after_disable"],
           "disabling removes menu entries %s and operators %s"
           % (a["menu_entries_after_disable"], a["operators_after_disable"]))

    for n, op, p, u, ax in cases:
        ref = f.info(p, u)
        if n.endswith(".tfx") or n.startswith("sintel"):
            c.equal("format", ref.get("format"), n.rsplit(".", 1)[1], n + " (follicle info)")
        b = scaled(ref["bounds"], UNIT_M[ref["unit"]])
        if ax == "Y_UP":
            b, note = yup_to_zup(b), "units %s, add-on axis Y_UP: (x, y, z) -> (x, -z, y)" % u
        else:
            note = "units %s, add-on axis Z_UP: axes kept" % u
        s = step_result(res, n)
        check_groom(c, s, ref, "%s (add-on)" % n, b, note, u.upper())
        if n.startswith("thick") and "measure" in s:
            m = s["measure"]
            c.true(abs(m["radius_min"] - rmin) <= 1e-6 * rmin and
                   abs(m["radius_max"] - rmax) <= 1e-6 * rmax,
                   "%s: point radius = thickness / 2: Blender [%.6g, %.6g] m, file [%.6g, %.6g] m"
                   % (n, m["radius_min"], m["radius_max"], rmin, rmax))
    s = step_result(res, "truncated.hair")
    err = s.get("import_error", "")
    c.true("truncated.hair" in err and "truncated" in err,
           "truncated.hair: the add-on refuses it naming the file: %r" % err)
    p = subprocess.run([f.exe, "info", bad_hair], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    c.true(p.returncode == 1, "truncated.hair: follicle info refuses it too (exit %d: %s)"
           % (p.returncode, p.stderr.strip()))


TESTS = {
    "import-obj": test_import_obj,
    "import-ply": test_import_ply,
    "import-gltf": test_import_gltf,
    "import-hair-obj": test_import_hair_obj,
    "export-mesh": test_export_mesh,
    "groom-addon": test_groom_addon,
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--follicle", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--work-dir", required=True)
    ap.add_argument("--blender", default="", help="blender executable (default: on PATH)")
    ap.add_argument("test", choices=sorted(TESTS))
    a = ap.parse_args()
    blender = find_blender(a.blender)
    if not blender:
        print("SKIP: Blender is not installed (no 'blender' on PATH, --blender=%r, "
              "FOLLICLE_BLENDER unset); apt-get install blender to run the interop tests"
              % a.blender)
        return SKIP
    work = os.path.abspath(a.work_dir)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    c = Checker()
    t = time.time()
    try:
        TESTS[a.test](c, Follicle(os.path.abspath(a.follicle), os.path.abspath(a.source_dir)),
                      blender, work)
    except (RuntimeError, subprocess.TimeoutExpired, KeyError, OSError) as e:
        c.fail("%s: %s: %s" % (a.test, type(e).__name__, e))
    print("%s: %d checks passed, %d failed (%.1f s)" % (a.test, c.passed, len(c.failures),
                                                        time.time() - t))
    if c.failures:
        print("FAILURES:\n  " + "\n  ".join(c.failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
