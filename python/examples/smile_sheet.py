#!/usr/bin/env python3
"""A face going from neutral to a full smile, frame by frame, with the hair riding the skin.

Renders the default scene (Lee Perry-Smith head, swept-back hair) at increasing smile weights and
writes one contact sheet PNG. Usage (from the repository root, after building):

    PYTHONPATH=build/release/python /usr/bin/python3 python/examples/smile_sheet.py out/smile_sheet.png
"""
import argparse
from pathlib import Path

import numpy as np

import follicle


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output", type=Path, help="contact sheet PNG")
    ap.add_argument("--scene", default=Path(__file__).resolve().parents[2] / "data/scenes/default.json")
    ap.add_argument("--size", type=int, default=320, help="pixels per tile")
    ap.add_argument("--steps", type=int, default=4, help="smile weights from 0 to 1")
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args()

    scene = follicle.Scene(args.scene, threads=args.threads)
    tiles = []
    for frame, w in enumerate(np.linspace(0.0, 1.0, args.steps)):
        scene.set_expression(0, "smile", weight=float(w))
        face = scene.skin_mesh(0, frame=frame)
        hair = scene.hair_strands(0, frame=frame)
        print(f"smile {w:.2f}: {face.num_vertices} skin vertices, {hair.num_strands} strands")
        tiles.append(scene.render(frame=frame, width=args.size, height=args.size))
    sheet = np.concatenate(tiles, axis=1)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    follicle.write_png(args.output, sheet)
    print(f"wrote {args.output} ({sheet.shape[1]}x{sheet.shape[0]})")


if __name__ == "__main__":
    main()
