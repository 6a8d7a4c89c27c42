"""Follicle from Python: skin wrinkles and hair (Anjyo 1992, Daldegan 1993, Bando 2002/2003).

Lengths are metres. Meshes and grooms are converted from their file's units on load::

    import follicle
    head = follicle.load_mesh("data/meshes/lee_perry_smith/head.obj", units="m")
    head.vertices      # (N, 3) float64 [m]
    scene = follicle.Scene("data/scenes/anjyo_shake.json", threads=2)
    img = scene.render(frame=10)          # (H, W, 4) uint8
    hair = scene.hair_strands(0, frame=10)  # the simulation stepped to frame 10

Errors raise follicle.Error (a RuntimeError) with the message the command-line tool prints.
"""
from ._follicle import (  # noqa: F401
    Error,
    Mesh,
    Scene,
    Strands,
    __version__,
    load_mesh,
    load_strands,
    write_png,
)

__all__ = ["Error", "Mesh", "Scene", "Strands", "load_mesh", "load_strands", "write_png"]
