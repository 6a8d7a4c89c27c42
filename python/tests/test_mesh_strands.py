"""follicle.load_mesh / load_strands / Mesh / Strands: units, shapes, round trips, bad input."""
import numpy as np
import pytest

import follicle

TORUS = "data/meshes/torus/torus.obj"
TFX = "data/grooms/sintel/sintel_hair.tfx"


def test_mesh_arrays_have_the_documented_shapes_and_types(root):
    m = follicle.load_mesh(root / TORUS, units="m")
    assert m.vertices.shape == (m.num_vertices, 3) and m.vertices.dtype == np.float64
    assert m.faces.shape == (m.num_faces, 3) and m.faces.dtype == np.int32
    assert m.num_faces > 0 and m.faces.min() >= 0 and m.faces.max() < m.num_vertices
    n = np.linalg.norm(m.normals, axis=1)
    assert np.allclose(n, 1.0, atol=1e-9)
    b = m.bounds
    assert np.allclose(b[0], m.vertices.min(axis=0)) and np.allclose(b[1], m.vertices.max(axis=0))


def test_units_scale_exactly_to_metres(root):
    in_m = follicle.load_mesh(root / TORUS, units="m").vertices
    in_mm = follicle.load_mesh(root / TORUS, units="mm").vertices
    in_cm = follicle.load_mesh(root / TORUS, units="cm").vertices
    np.testing.assert_allclose(in_mm * 1000.0, in_m, rtol=1e-12)
    np.testing.assert_allclose(in_cm * 100.0, in_m, rtol=1e-12)


@pytest.mark.parametrize("ext", [".obj", ".ply", ".glb"])
def test_mesh_round_trip_through_every_writer(root, tmp_path, ext):
    m = follicle.load_mesh(root / TORUS, units="m")
    out = tmp_path / ("torus" + ext)
    units = "m" if ext == ".glb" else "mm"  # glTF is metres by specification
    m.save(out, units=units)
    back = follicle.load_mesh(out, units=units)
    assert back.num_faces == m.num_faces
    np.testing.assert_allclose(back.bounds, m.bounds, atol=1e-6)


def test_gltf_in_other_units_is_refused(root, tmp_path):
    m = follicle.load_mesh(root / TORUS, units="m")
    with pytest.raises(follicle.Error, match="glTF stores metres by specification"):
        m.save(tmp_path / "torus.glb", units="mm")


def test_mesh_from_arrays_computes_outward_normals():
    # A tetrahedron with counter-clockwise faces seen from outside.
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    f = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    m = follicle.Mesh(v, f)
    centre = np.mean(m.vertices, axis=0)
    outward = np.einsum("ij,ij->i", m.normals, m.vertices - centre)
    assert (outward > 0).all()


def test_bad_mesh_input_raises_follicle_error():
    with pytest.raises(follicle.Error, match=r"faces\[0\]\[2\] = 7 is not a vertex index"):
        follicle.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 7]])
    with pytest.raises(follicle.Error, match=r"expected shape \(N, 3\)"):
        follicle.Mesh([[0, 0], [1, 0]], [[0, 1, 2]])
    with pytest.raises(follicle.Error, match=r"vertex 0 has a non-finite coordinate"):
        follicle.Mesh([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def test_errors_carry_the_cli_message(root, cli, tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(follicle.Error) as e:
        follicle.load_mesh(bad, units="m")
    assert str(bad) in str(e.value)
    r = cli("info", bad, "--units", "m")
    assert r.returncode != 0
    assert str(e.value) in r.stderr, (str(e.value), r.stderr)
    with pytest.raises(follicle.Error, match="mm"):
        follicle.load_mesh(root / TORUS, units="furlong")
    with pytest.raises(follicle.Error, match="missing.obj"):
        follicle.load_mesh(tmp_path / "missing.obj")


def test_strands_of_an_imported_groom(root, cli):
    s = follicle.load_strands(root / TFX, units="cm")
    assert s.points.shape == (s.num_points, 3) and s.points.dtype == np.float32
    sizes = s.strand_sizes
    assert sizes.shape == (s.num_strands,) and int(sizes.sum()) == s.num_points
    assert (s.offsets[1:] - s.offsets[:-1] == sizes).all()
    np.testing.assert_array_equal(s.roots, s.points[s.offsets[:-1]])
    np.testing.assert_array_equal(s.strand(3), s.points[s.offsets[3]:s.offsets[4]])
    # The CLI reports the same counts.
    r = cli("info", TFX, "--units", "cm")
    assert r.returncode == 0, r.stderr
    assert f"strands: {s.num_strands}\n" in r.stdout, r.stdout
    in_m = follicle.load_strands(root / TFX, units="m").points
    np.testing.assert_allclose(in_m * 0.01, s.points, rtol=1e-6)


@pytest.mark.parametrize("ext", [".hair", ".tfx", ".usda", ".obj"])
def test_strands_round_trip(tmp_path, ext):
    rng = np.random.default_rng(3)
    sizes = np.array([4, 7, 2, 5])
    pts = np.cumsum(rng.normal(scale=0.01, size=(sizes.sum(), 3)), axis=0).astype(np.float32)
    s = follicle.Strands(pts, sizes)
    out = tmp_path / ("groom" + ext)
    s.save(out, units="cm")
    back = follicle.load_strands(out, units="cm")
    assert back.num_strands == 4
    if ext != ".tfx":  # .tfx resamples every strand to a fixed count
        np.testing.assert_array_equal(back.strand_sizes, sizes)
        np.testing.assert_allclose(back.points, pts, atol=2e-6)


def test_bad_strand_input_raises():
    with pytest.raises(follicle.Error, match="add up to 5 but there are 6 points"):
        follicle.Strands(np.zeros((6, 3)), [2, 3])
    with pytest.raises(follicle.Error, match="a strand needs 2 points"):
        follicle.Strands(np.zeros((3, 3)), [1, 2])
    with pytest.raises(IndexError):
        follicle.Strands(np.zeros((3, 3)), [3]).strand(1)
