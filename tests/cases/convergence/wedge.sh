# Sourced by the case tests wedgeA/run and wedgeB/run: the tutorial's Allrun at its coarsest
# resolution, h0/l0 = 4, and the checks both wedges share.  The caller sets
#     name       the tutorial (tutorials/convergence/<name>)
#     laid       the inlet where particleGen laid the pool out [m]
#     tol_relL2, tol_peak, tol_load    the tolerances (fractions)
#     tol_inlet  (optional, 1e-4 m) how far the inlet meniscus may stand from the pool laid out
# and says why in its header.  Checked: Allrun exits 0 (no particle through a wall: lubFoam
# stops with exit 2 then); the fluid particle count stays (totals); the wall load of every
# step of the averaging window within 10% of the window's mean (function wallLoad; issue
# 26: one steady film, no step whose pressure collapsed); the inlet meniscus found by
# probe film within 0.1 mm of where the pool was laid out (the pool grows or shrinks by
# what the plate brings against what the contact passes); the errors of the mean wall
# pressure against reynoldsRef from that meniscus within the tolerances.
set -u
top=$(cd ../../../.. && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export LUB_TOP=$top
export OMP_NUM_THREADS=1

ok() { echo "PASS $1"; }
ko() { echo "FAIL $1${2:+: $2}"; }
check() { if eval "$2"; then ok "$1"; else ko "$1" "${3:-}"; fi; }
within() { awk -v v="$1" -v t="$2" 'BEGIN { if (v < 0) v = -v; exit !(v != "" && v <= t) }'; }

c=$tmp/case
cp -r "$top/tutorials/convergence/$name" "$c"
(cd "$c" && ./Allclean >/dev/null 2>&1)
(cd "$c" && ./Allrun >"$tmp/allrun.log" 2>&1)
rc=$?
check "Allrun (h0/l0 = 4) exits 0" "[ $rc -eq 0 ]" "exit $rc: $(tail -n 20 "$tmp/allrun.log")"

tot=$c/postProcessing/totals/0/totals.dat
check "the fluid particle count stays (totals)" \
    "awk '!/^#/ { n++; if (f == \"\") f = \$7; else if (\$7 != f) bad = 1 } END { exit bad || n < 5 }' '$tot'" \
    "$(head -3 "$tot")"
ld=$c/postProcessing/wallLoad/0/load.dat
range=$(awk '!/^#/ { n++; s += $2; l[n] = $2 } END { m = s / n; for (k = 1; k <= n; k++) { d = (l[k] - m) / m
             if (d < lo) lo = d; if (d > hi) hi = d }; printf "%d %.4f %.4f", n, lo, hi }' "$ld")
set -- $range
check "the wall load of every one of the $1 steps of the window within 10% of its mean ($2 to $3)" \
    "within '$2' 0.1 && within '$3' 0.1" "$range"
xin=$(sed -n 's/^# inletMeniscus x = \([^ ]*\).*/\1/p' "$c/postProcessing/probe/film.dat")
tol_inlet=${tol_inlet:-1e-4}
check "the inlet meniscus ($xin m) within $tol_inlet m of the pool laid out ($laid m)" \
    "within \$(awk -v a='$xin' -v b='$laid' 'BEGIN { print a - b }') $tol_inlet" "$(head -5 "$c/postProcessing/probe/film.dat")"
for e in relL2:$tol_relL2 peakErr:$tol_peak integralErr:$tol_load; do
    v=$(sed -n "s/^${e%:*} //p" "$c/log.postErr")
    check "${e%:*} against Reynolds from the inlet meniscus: $v within ${e#*:}" "within '$v' ${e#*:}" \
        "$(cat "$c/log.postErr")"
done
exit 0
