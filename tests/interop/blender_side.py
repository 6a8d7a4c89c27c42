# Runs inside Blender (blender -b --factory-startup --python-exit-code 1 --python THIS -- JOB.json):
# imports files with Blender's own importers (or the Follicle groom add-on), measures what Blender
# made of them and optionally exports them again. It only measures; the driver
# (blender_interop.py) compares the numbers with what `follicle info` reports.
#
# JOB.json: {"result": "out.json",
#            "addon": {"file": ".../follicle_grooms.py", "module": "follicle_grooms"},  # optional
#            "steps": [{"name": "...",
#                       "import": {"op": "wm.obj_import", "kwargs": {...}},
#                       "measure": "mesh" | "edges" | "curves",
#                       "export": {"op": "wm.obj_export", "kwargs": {...}}}, ...]}  # optional
# Every step starts from an empty scene. Measurements are in Blender world coordinates (object
# matrices applied), metres. Any failure raises, so Blender exits 1 (--python-exit-code 1).
import json
import os
import sys
import time

import bpy
import numpy as np

# Debian's Blender 3.4.1 glTF add-on calls np.bool, which NumPy >= 1.24 (Debian 12 ships 1.24.2)
# removed: without this alias every glTF import fails with "module 'numpy' has no attribute
# 'bool'". It is a Blender/Debian packaging mismatch, not a Follicle issue (docs/blender.md).
if "bool" not in np.__dict__:
    np.bool = bool


def op_by_name(name):
    mod, fn = name.split(".")
    return getattr(getattr(bpy.ops, mod), fn)


def clear_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.curves, bpy.data.materials, bpy.data.images):
        for d in list(coll):
            if d.users == 0:
                coll.remove(d)


def world_coords(obj, local):
    m = np.array(obj.matrix_world, dtype=np.float64)
    return local @ m[:3, :3].T + m[:3, 3]


def bounds(pts):
    if len(pts) == 0:
        return None
    return {"min": pts.min(axis=0).tolist(), "max": pts.max(axis=0).tolist()}


def identity(obj):
    return bool(np.allclose(np.array(obj.matrix_world), np.eye(4), atol=1e-12))


def mesh_arrays(obj):
    me = obj.data
    co = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", co)
    ed = np.empty(2 * len(me.edges), dtype=np.int64)
    me.edges.foreach_get("vertices", ed)
    nl = np.empty(len(me.polygons), dtype=np.int64)
    me.polygons.foreach_get("loop_total", nl)
    return world_coords(obj, co.reshape(-1, 3).astype(np.float64)), ed.reshape(-1, 2), nl


def components(n, edges):
    """Connected components of an edge graph on n vertices: (count, sizes)."""
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in edges.tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[ra] = rb
    roots = np.fromiter((find(i) for i in range(n)), dtype=np.int64, count=n)
    _, sizes = np.unique(roots, return_counts=True)
    return len(sizes), sizes


def measure_meshes(objs, as_edges):
    meshes = [o for o in objs if o.type == "MESH"]
    out = {"objects": len(objs), "mesh_objects": len(meshes),
           "object_types": sorted({o.type for o in objs}),
           "identity_matrix": all(identity(o) for o in meshes)}
    pts, all_edges, loops, base = [], [], [], 0
    for o in meshes:
        p, e, nl = mesh_arrays(o)
        pts.append(p)
        all_edges.append(e + base)
        loops.append(nl)
        base += len(p)
    pts = np.concatenate(pts) if pts else np.zeros((0, 3))
    edges = np.concatenate(all_edges) if all_edges else np.zeros((0, 2), dtype=np.int64)
    nl = np.concatenate(loops) if loops else np.zeros(0, dtype=np.int64)
    out.update(vertices=int(len(pts)), edges=int(len(edges)), polygons=int(len(nl)),
               triangles=int((nl == 3).sum()), non_triangles=int((nl != 3).sum()),
               bounds=bounds(pts))
    if as_edges:
        deg = np.bincount(edges.ravel(), minlength=len(pts)) if len(edges) else \
            np.zeros(len(pts), dtype=np.int64)
        count, sizes = components(len(pts), edges)
        lengths = np.linalg.norm(pts[edges[:, 0]] - pts[edges[:, 1]], axis=1) if len(edges) else \
            np.zeros(0)
        out.update(components=int(count),
                   component_min=int(sizes.min()) if count else 0,
                   component_max=int(sizes.max()) if count else 0,
                   branching_vertices=int((deg > 2).sum()),
                   total_edge_length=float(lengths.sum()))
    return out


def measure_curves(objs):
    curves = [o for o in objs if o.type == "CURVE"]
    out = {"objects": len(objs), "curve_objects": len(curves),
           "object_types": sorted({o.type for o in objs}),
           "identity_matrix": all(identity(o) for o in curves)}
    sizes, lengths, pts, types, radii = [], [], [], set(), []
    props = {}
    for o in curves:
        props = {k: o[k] for k in o.keys() if k.startswith("follicle_")}
        for sp in o.data.splines:
            types.add(sp.type)
            n = len(sp.points)
            co = np.empty(4 * n, dtype=np.float32)
            sp.points.foreach_get("co", co)
            r = np.empty(n, dtype=np.float32)
            sp.points.foreach_get("radius", r)
            p = world_coords(o, co.reshape(-1, 4)[:, :3].astype(np.float64))
            sizes.append(n)
            lengths.append(float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()))
            pts.append(p)
            radii.append(r)
    pts = np.concatenate(pts) if pts else np.zeros((0, 3))
    radii = np.concatenate(radii) if radii else np.zeros(0)
    out.update(splines=len(sizes), points=int(sum(sizes)),
               points_min=min(sizes) if sizes else 0, points_max=max(sizes) if sizes else 0,
               spline_types=sorted(types), bounds=bounds(pts),
               length_min=min(lengths) if lengths else 0.0,
               length_mean=float(np.mean(lengths)) if lengths else 0.0,
               length_max=max(lengths) if lengths else 0.0,
               radius_min=float(radii.min()) if len(radii) else 0.0,
               radius_max=float(radii.max()) if len(radii) else 0.0,
               properties=props)
    return out


def setup_addon(spec):
    """Installs the add-on file the way a user does (Preferences > Add-ons > Install, into
    BLENDER_USER_SCRIPTS, which the driver points at a scratch folder) and enables it."""
    info = {}
    r = bpy.ops.preferences.addon_install(filepath=spec["file"], overwrite=True)
    info["install"] = sorted(r)
    r = bpy.ops.preferences.addon_enable(module=spec["module"])
    info["enable"] = sorted(r)
    import addon_utils

    info["enabled"] = bool(addon_utils.check(spec["module"])[1])
    mod = sys.modules[spec["module"]]
    info["module_file"] = mod.__file__
    info["bl_info_name"] = mod.bl_info.get("name", "")
    info["bl_info_category"] = mod.bl_info.get("category", "")
    draw = [f.__name__ for f in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()]
    info["import_menu_entries"] = [d for d in draw if d in ("menu_func_hair", "menu_func_tfx")]
    info["operators"] = [n for n in ("follicle_hair", "follicle_tfx")
                         if hasattr(bpy.types, "IMPORT_CURVE_OT_" + n)]
    # unregister() must undo register(): disable, check, enable again for the steps.
    bpy.ops.preferences.addon_disable(module=spec["module"])
    draw = [f.__name__ for f in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()]
    info["menu_entries_after_disable"] = [d for d in draw
                                          if d in ("menu_func_hair", "menu_func_tfx")]
    info["operators_after_disable"] = [n for n in ("follicle_hair", "follicle_tfx")
                                       if hasattr(bpy.types, "IMPORT_CURVE_OT_" + n)]
    bpy.ops.preferences.addon_enable(module=spec["module"])
    return info


def run_step(step):
    clear_scene()
    res = {"name": step["name"]}
    before = set(bpy.data.objects)
    imp = step["import"]
    t = time.time()
    try:
        op = op_by_name(imp["op"])
        op.get_rna_type()  # raises KeyError when Blender has no such operator
    except (AttributeError, KeyError):
        res["missing_operator"] = imp["op"]
        return res
    try:
        r = op(**imp.get("kwargs", {}))
    except RuntimeError as e:  # an operator that reported an error
        res["import_error"] = str(e).strip()
        return res
    res["import_result"] = sorted(r)
    res["import_seconds"] = round(time.time() - t, 3)
    objs = [o for o in bpy.data.objects if o not in before]
    kind = step["measure"]
    if kind == "curves":
        res["measure"] = measure_curves(objs)
    else:
        res["measure"] = measure_meshes(objs, as_edges=(kind == "edges"))
    exp = step.get("export")
    if exp:
        bpy.ops.object.select_all(action="DESELECT")
        for o in objs:
            o.select_set(True)
        if objs:
            bpy.context.view_layer.objects.active = objs[0]
        t = time.time()
        r = op_by_name(exp["op"])(**exp.get("kwargs", {}))
        res["export_result"] = sorted(r)
        res["export_seconds"] = round(time.time() - t, 3)
    return res


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) != 1:
        raise SystemExit("usage: blender -b --python blender_side.py -- JOB.json")
    with open(argv[0]) as f:
        job = json.load(f)
    out = {"blender_version": bpy.app.version_string, "steps": []}
    if "addon" in job:
        out["addon"] = setup_addon(job["addon"])
    for step in job["steps"]:
        out["steps"].append(run_step(step))
    tmp = job["result"] + ".tmp"
    with open(tmp, "w") as f:
        json.dump(out, f, indent=1)
    os.replace(tmp, job["result"])


main()
