#!/bin/sh
# Every run quoted in README.md (issue 22, single sheet and first guidance deck).
# Run from the repository root. Solid runs take 1-10 min each on one core
# (ccx 2.20, nice 10, OMP_NUM_THREADS=1); the fine mesh about 30 min.
set -e
S=research/sheet22/sheet.py
R=research/sheet22/results
mkdir -p $R
L="--loads 0,0.5,1,1.5 --incs 4"
# b = 0.03, t varied (b/t = 5, 10, 30, 60), nu = 0 with G = E/2.6
for t in 0.006 0.003 0.001 0.0005; do
  python3 $S solid --t $t $L --out /tmp/s22/c_t${t}_nu0 > $R/solid_t${t}_nu0_50x8x2.csv
  python3 $S beam  --t $t --mat nu0 --loads 0,0.5,1,1.5 --n 40 --out /tmp/s22/b_t${t}_nu0 > $R/beam_t${t}_nu0_n40.csv
done
# b/t = 30 with 10 increments per step (the stored reference of the warping tests)
python3 $S solid --loads 0,0.5,1,1.5 --incs 10 --out /tmp/s22/c_bt30_incs10 > fixtures/curves/solid/solid_t0.001_nu0_50x8x2_incs10.csv
# mesh convergence, b/t = 30
python3 $S solid $L --nl 100 --nh 16 --out /tmp/s22/c_bt30_nu0_fine > $R/solid_t0.001_nu0_100x16x2.csv
# beam convergence
for n in 20 80; do python3 $S beam --loads 0,0.5,1,1.5 --n $n --out /tmp/s22/b_n$n > $R/beam_t0.001_nu0_n$n.csv; done
# the clamp's warping restraint removed (u_y = c x z left free at the clamp)
python3 $S solid $L --clamp warpfree --out /tmp/s22/c_bt30_nu0_wf > $R/solid_t0.001_nu0_50x8x2_warpfree.csv
# b/L halved at b/t = 30
python3 $S solid --b 0.015 --t 0.0005 --nl 100 --nh 8 $L --out /tmp/s22/c_b015 > $R/solid_b0.015_t0.0005_nu0_100x8x2.csv
python3 $S solid --b 0.015 --t 0.0005 --nl 100 --nh 8 $L --clamp warpfree --out /tmp/s22/c_b015_wf > $R/solid_b0.015_t0.0005_nu0_100x8x2_warpfree.csv
python3 $S beam  --b 0.015 --t 0.0005 --mat nu0 --loads 0,0.5,1,1.5 --n 40 --out /tmp/s22/b_b015 > $R/beam_b0.015_t0.0005_nu0_n40.csv
# materials: isotropic nu = 0 (G = E/2) and nu = 0.3
for m in nu0g2 nu03; do
  python3 $S solid --mat $m $L --out /tmp/s22/c_bt30_$m > $R/solid_t0.001_${m}_50x8x2.csv
  python3 $S beam  --mat $m --loads 0,0.5,1,1.5 --n 40 --out /tmp/s22/b_t0.001_$m > $R/beam_t0.001_${m}_n40.csv
done
# closed form at rest
for t in 0.006 0.003 0.001 0.0005; do python3 research/sheet22/vlasov.py 0.03 $t 0.2; done > $R/vlasov_at_rest.txt
python3 research/sheet22/vlasov.py 0.03 0.001 0.2 0.5 >> $R/vlasov_at_rest.txt
python3 research/sheet22/vlasov.py 0.015 0.0005 0.2 >> $R/vlasov_at_rest.txt
# guidance (first draft deck), and flexmb at the same strokes
python3 research/sheet22/guidance.py --xs 0,0.02,0.04,0.06,0.0834 --nl 50 --nh 8 --modes 8 --out /tmp/s22/guid_50x8 > fixtures/curves/solid/solid_guidance_nu0_50x8x2.csv
python3 research/sheet22/guidance_beam.py > $R/beam_guidance_nu0.csv
# guidance with the warping of the two base clamps freed (the body end stays rigid)
python3 research/sheet22/guidance.py --clamp warpfree --xs 0.02,0.0834 --incs 6 --nl 50 --nh 8 --modes 8 --out /tmp/s22/guid_50x8_wf > fixtures/curves/solid/solid_guidance_nu0_50x8x2_warpfree.csv
# twist shapes, clamped and warp-free, at rest and alpha = 1.5
for c in full warpfree; do
  python3 $S solid --edges --clamp $c --loads 0,1.5 --incs 10 --modes 6 --out /tmp/s22/edges_$c > $R/solid_t0.001_nu0_50x8x2_edges_$c.csv
  python3 research/sheet22/twist.py /tmp/s22/edges_$c > $R/twist_t0.001_nu0_50x8x2_$c.csv
done
# guidance, fine mesh (about 15 min on one core)
python3 research/sheet22/guidance.py --xs 0.04,0.0834 --incs 5 --nl 100 --nh 16 --modes 6 --out /tmp/s22/guid_100x16 > fixtures/curves/solid/solid_guidance_nu0_100x16x2.csv
# guidance, physical steel (nu = 0.3; about 5 min on one core)
python3 research/sheet22/guidance.py --mat nu03 --xs 0,0.02,0.04,0.06,0.0834 --nl 50 --nh 8 --modes 8 --out /tmp/s22/guid_50x8_nu03 > fixtures/curves/solid/solid_guidance_nu03_50x8x2.csv
