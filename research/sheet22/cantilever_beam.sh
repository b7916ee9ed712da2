#!/bin/sh
# The clamped sheet of sheet.py (height B, default 0.03 m, L = 0.2 m, thickness T) as flexmb
# warping beams (n = 40, warping Restrained at the clamp, Free at the tip),
# without and with `anticlastic` (Restrained, Free), ν = 0.3, at the loads
# α = P L²/EI = 0.5, 1, 1.5: the static tip position (x, y, z) and the first
# six frequencies of `flexmb sweep --over load` at the load.
#   T=0.001 sh research/sheet22/cantilever_beam.sh > results/beam_t0.001_nu03_anticlastic.txt
# FLEXMB: the binary (default target/release/flexmb).
set -e
T=${T:-0.001}
B=${B:-0.03}
F=${FLEXMB:-target/release/flexmb}
D=${TMPDIR:-/tmp}/s22_cantilever_${B}_$T
mkdir -p "$D"
EI=$(python3 -c "print(2.1e11 * $B * $T**3 / 12)")
for model in warping anticlastic; do
  opt=""
  [ "$model" = anticlastic ] && opt=", anticlastic: Some((p: Restrained, q: Free))"
  for al in 0.5 1 1.5; do
    P=$(python3 -c "print($al * $EI / 0.2**2)")
    cat > "$D/c.ron" <<EOR
(
    name: "clamped sheet b = $B, t = $T",
    dimension: Spatial,
    gravity: None,
    materials: { "steel": (e: 2.1e11, nu: 0.3, rho: 7600.0) },
    sections: { "sheet": Rectangle(by: $B, bz: $T) },
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [0.0, 0.2, 0.0]) ],
    elements: [ (id: "sheet", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet", up: Some([0.0, 0.0, 1.0]), n: 40, warping: Some((p: Restrained, q: Free))$opt))) ],
    fixed: [Node("A")],
    rigid: [],
    dofs: Deformations,
    loads: [ (node: "B", force: Some([$P, 0.0, 0.0]), function: Some(Constant(1.0))) ],
    outputs: [Position("B")],
)
EOR
    "$F" static "$D/c.ron" --steps 20 --out "$D/static" > /dev/null
    "$F" sweep "$D/c.ron" --over load --from 0 --to 1 --n 3 --modes 6 --out "$D/sweep" > /dev/null
    echo "$model,alpha=$al,tip=$(sed -n 5p "$D/static/node_positions.csv"),f=$(grep -v '^#' "$D/sweep/eigenfrequencies.csv" | sed -n 4p | cut -d, -f2-7)"
  done
done
