#!/usr/bin/env bash
# The main job: installs and builds what is missing, then runs the liver demo: the bundled liver
# (liver2.msh, 1,493 tetrahedra, scaled to 17 cm) hanging from its upper surface under gravity,
# simulated with the generalized particle system and constant-Q viscoelasticity (Q = 4.8, three
# memory variables, no artificial damping); frames go to out/liver-demo (ParaView).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build"
exec "$root/build/tools/viscera-sim/viscera-sim" \
  --mesh "$root/data/meshes/liver2.msh" --scale 0.08 \
  --material "$root/data/materials/liver-viscoelastic.json" \
  --model gps_energy --damping 0 --fix-slab z,max,0.2 --duration 2 \
  --out "$root/out/liver-demo" "$@"
