"""follicle.Scene: renders like the CLI, steps hair deterministically, poses faces frame by frame."""
import threading

import numpy as np
import pytest

import follicle

DEFAULT = "data/scenes/default.json"  # skin rig ('troubled') with hair riding the skin, still
SHAKE = "data/scenes/anjyo_shake.json"  # a bob on a shaking head, 72 frames
TRACK = "data/scenes/hair_expression.json"  # expression track with hair riding the skin


def test_render_gives_the_cli_image(root, cli, tmp_path):
    sc = follicle.Scene(root / DEFAULT, threads=2)
    img = sc.render(width=96, height=64)
    assert img.shape == (64, 96, 4) and img.dtype == np.uint8
    assert img[..., :3].std() > 5, "blank image"
    assert sc.size == (800, 800), "a size given to render() must not stick"
    follicle.write_png(tmp_path / "py.png", img)
    r = cli("--threads", 2, "-q", "render", DEFAULT, "-o", tmp_path / "cli.png", "--width", 96,
            "--height", 64)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()


def test_hair_steps_from_the_groom_and_is_thread_independent(root):
    one = follicle.Scene(root / SHAKE, threads=1)
    two = follicle.Scene(root / SHAKE, threads=2)
    assert one.frame_count == 72 and one.frame_time(24) == pytest.approx(1.0)
    assert one.hair_groups == ["bob"] or len(one.hair_groups) == 1
    groom = one.hair_groom(0)
    f0 = one.hair_strands(0, frame=0)
    np.testing.assert_allclose(f0.points, groom.points, atol=1e-7)  # through the head frame
    a = [one.hair_strands(0, frame=f).points for f in (6, 12)]
    b = [two.hair_strands(0, frame=f).points for f in (6, 12)]
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert np.abs(a[1] - f0.points).max() > 1e-3, "the shake must move the hair"
    # The roots stay on the shaking head.
    s12 = one.hair_strands(0, frame=12)
    np.testing.assert_allclose(s12.roots, one.hair_root_targets(0, frame=12), atol=1e-4)


def test_expressions_set_frame_by_frame_move_skin_and_hair(root):
    sc = follicle.Scene(root / DEFAULT, threads=2)
    assert "smile" in sc.expression_names(0)
    assert "zygomatic_major_L" in sc.muscle_names(0)
    scene_pose = sc.skin_mesh(0).vertices
    hair_scene = sc.hair_strands(0).points
    # Frame by frame: more smile, more displacement of the mouth corners.
    moved = []
    rest = None
    for f, w in enumerate([0.0, 0.5, 1.0]):
        sc.set_contractions(0, {"zygomatic_major_L": w, "zygomatic_major_R": w})
        v = sc.skin_mesh(0, frame=f).vertices
        if rest is None:
            rest = v
        moved.append(np.linalg.norm(v - rest, axis=1).max())
    assert moved[0] == 0.0 and 1e-4 < moved[1] < moved[2], moved
    # The hair rides the posed skin: its roots sit on their targets for the new pose.
    sc.set_expression(0, "surprise", weight=1.0)
    hair = sc.hair_strands(0)
    np.testing.assert_allclose(hair.roots, sc.hair_root_targets(0), atol=1e-5)
    assert np.abs(hair.points - hair_scene).max() > 1e-4, "raised brows must lift the fringe"
    # Back to the scene's own expression, bit for bit.
    sc.clear_pose(0)
    np.testing.assert_array_equal(sc.skin_mesh(0).vertices, scene_pose)
    np.testing.assert_array_equal(sc.hair_strands(0).points, hair_scene)


def test_pose_overrides_a_track_and_the_render_changes(root):
    sc = follicle.Scene(root / TRACK, threads=2)
    tracked = sc.skin_mesh(0, frame=40).vertices  # surprise on the track
    sc.set_expression(0, "neutral")
    neutral = sc.skin_mesh(0, frame=40).vertices
    assert np.abs(tracked - neutral).max() > 1e-4
    a = sc.render(frame=40, width=64, height=64)
    sc.set_expression(0, "angry", weight=1.0, jaw_angle=0.2)
    b = sc.render(frame=40, width=64, height=64)
    assert np.abs(a.astype(int) - b.astype(int)).max() > 10


def test_errors_name_what_is_wrong(root, cli, tmp_path):
    sc = follicle.Scene(root / DEFAULT, threads=1)
    with pytest.raises(follicle.Error, match=r'unknown expression "smiel" \(did you mean "smile"\?\)'):
        sc.set_expression(0, "smiel")
    with pytest.raises(follicle.Error, match="zygomatic"):
        sc.set_contractions(0, {"zygomatic_major": 1.0})
    with pytest.raises(follicle.Error, match="out of range"):
        sc.skin_mesh(3)
    with pytest.raises(follicle.Error, match="frame must be >= 0"):
        sc.render(frame=-1)
    with pytest.raises(follicle.Error, match="not finite"):
        sc.set_expression(0, "smile", weight=float("nan"))
    bad = tmp_path / "bad.json"
    bad.write_text('{"follicle_scene": 1,\n "render": {"width": -3}}\n')
    with pytest.raises(follicle.Error) as e:
        follicle.Scene(bad)
    r = cli("validate", bad)
    assert r.returncode != 0 and str(e.value) in r.stderr, (str(e.value), r.stderr)


def test_long_calls_release_the_gil(root):
    sc = follicle.Scene(root / SHAKE, threads=1)
    ticks = 0
    t = threading.Thread(target=lambda: sc.hair_strands(0, frame=48))
    t.start()
    while t.is_alive():  # runs while the simulation does only if the call released the GIL
        ticks += 1
        t.join(0.001)
    assert ticks > 20, ticks
