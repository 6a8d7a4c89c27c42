#!/usr/bin/env bash
# Installs dependencies, builds, and renders the demo outputs into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
JOBS=${JOBS:-$(nproc)}
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS" --target follicle
FOLLICLE=build/release/apps/cli/follicle
mkdir -p out
"$FOLLICLE" render data/scenes/default.json -o out/default.png
echo "demo: wrote out/default.png"
# Anjyo 1992 hair: the bob (Fig. 3) at full density, and the wind-gust clip (Fig. 10) as MP4.
"$FOLLICLE" render data/scenes/anjyo_bob.json -o out/anjyo-bob.png
echo "demo: wrote out/anjyo-bob.png"
"$FOLLICLE" animate data/scenes/anjyo_wind.json -o out/anjyo-wind-frames --mp4 out/anjyo-wind.mp4 \
  --cache out/anjyo-wind-cache
echo "demo: wrote out/anjyo-wind.mp4"
# Bando 2002 expressive wrinkles on the default head (Figs. 2.11, 2.13).
"$FOLLICLE" render data/scenes/skin_angry.json -o out/wrinkles-angry.png
echo "demo: wrote out/wrinkles-angry.png"
"$FOLLICLE" render data/scenes/skin_smile.json -o out/wrinkles-smile.png
echo "demo: wrote out/wrinkles-smile.png"
# Bando 2002 fine-scale and joint wrinkles on the skeleton-animated MakeHuman hand (Figs. 2.16,
# 2.17): a still frame and the finger-flexion clip.
"$FOLLICLE" render data/scenes/hand_rest.json -o out/hand.png
echo "demo: wrote out/hand.png"
"$FOLLICLE" animate data/scenes/hand_flexion_anim.json -o out/hand-frames --mp4 out/hand.mp4
echo "demo: wrote out/hand.mp4"
# Bando 2003 loosely connected particle hair blown by SPH wind (Fig. 3.9): the clip and one frame.
"$FOLLICLE" animate data/scenes/lcp_wind.json -o out/lcp-wind-frames --mp4 out/lcp-wind.mp4
cp out/lcp-wind-frames/frame_0024.png out/lcp-wind.png
echo "demo: wrote out/lcp-wind.png and out/lcp-wind.mp4"
# Daldegan 1993 (HairStyler, hinge dynamics, cylinder collision, shadow-buffer rendering): beard,
# moustache and eyebrows on the wrinkled face, long hair, fur, and the wind clip.
for s in daldegan_beard daldegan_long daldegan_fur; do
  "$FOLLICLE" render "data/scenes/$s.json" -o "out/${s//_/-}.png"
  echo "demo: wrote out/${s//_/-}.png"
done
# The wind clip (60 frames, a few minutes): see the README for the `animate` command.
"$FOLLICLE" render data/scenes/daldegan_wind.json --frame 40 -o out/daldegan-wind-frame40.png
echo "demo: wrote out/daldegan-wind-frame40.png"
# Hair on a face changing expression: the roots ride the deforming, wrinkling skin.
"$FOLLICLE" animate data/scenes/hair_expression.json -o out/hair-expression-frames \
  --mp4 out/hair-expression.mp4
echo "demo: wrote out/hair-expression.mp4"
