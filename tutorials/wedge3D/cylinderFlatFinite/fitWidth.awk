# The film's ends: the MPS rows of wall pressure across the roller against the finite-width
# Reynolds reference of rollers wider by 2 delta (tutorials/README.md, Roller of finite
# width).  Each row's load q(z) = int p dx (the roller's round-surface wall particles, the
# mean per bin of x times the bin, as the function wallLoad bins it) over the mid-plane
# row's, against the same ratio of the reference at that z: the rms of the difference over
# the rows measures the shape, whatever the level.  The delta of the smallest misfit
# (a parabola through the three smallest) is the width the MPS film has; at it, the
# mid-plane row's load and the roller's load (trapezoidal rule over all rows) against the
# reference's (its grid's trapezoidal rule in x and z; interpolated between the deltas).
#
#     awk -v l0=L0 -v R=R -v h0=H0 -v bin=BIN -v from=X0 -f fitWidth.awk WALL DELTAS REF...
#
# WALL: '# x y z p' per wall particle of the roller (probe wallPressure -patch cylinder
# -average); DELTAS: one line 'delta[m]' per REF, in the order given; REF: the reference's
# p2d.dat ('# x z p', x outer, z inner, z on a uniform grid from -W'/2 to W'/2).  Prints one
# line per delta and the fit: 'delta misfit midRow load' (the last two MPS/reference - 1).
BEGIN { CONVFMT = "%.17g" }
FILENAME == ARGV[1] {
    if (/^#/ || NF < 4) next
    # the round surface only: the end faces' wall particles lie above it
    hx = h0 + R - sqrt(R * R - $1 * $1)
    if ($2 > hx + l0 / 2) next
    k = sprintf("%.0f", $3 / l0) + 0; b = int(($1 - from) / bin)
    s[k, b] += $4; n[k, b]++; row[k] = 1
    if (b > bmax) bmax = b
    next
}
FILENAME == ARGV[2] { if (!/^#/ && NF) dl[++nd] = $1; next }
FNR == 1 { f++; nq = 0 }
!/^#/ && NF == 3 {
    z = $2 + 0
    if (!((f, z) in lx)) { zz[f, ++nq] = z; nz[f] = nq }
    else q[f, z] += 0.5 * ($3 + lp[f, z]) * ($1 - lx[f, z])
    lx[f, z] = $1; lp[f, z] = $3
}
# the reference's row load at z (linear between its grid lines; 0 outside)
function refq(f, z,   z0, dz, j, t) {
    z0 = zz[f, 1]; dz = zz[f, 2] - z0
    j = int((z - z0) / dz) + 1
    if (j < 1 || j >= nz[f]) return 0
    t = (z - zz[f, j]) / dz
    return (1 - t) * q[f, zz[f, j]] + t * q[f, zz[f, j + 1]]
}
END {
    if (nd != f) { print "fitWidth.awk: " nd " deltas for " f " reference tables" > "/dev/stderr"; exit 1 }
    kmin = 1e9; kmax = -1e9
    for (k in row) { k += 0; if (k < kmin) kmin = k; if (k > kmax) kmax = k }
    if (!(0 in row) || kmax - kmin < 4) { print "fitWidth.awk: no mid-plane row or fewer than 5 rows" > "/dev/stderr"; exit 1 }
    for (k = kmin; k <= kmax; k++) {
        qm[k] = 0
        for (b = 0; b <= bmax; b++) if (n[k, b]) qm[k] += s[k, b] / n[k, b] * bin
        load += (k == kmin || k == kmax ? 0.5 : 1) * qm[k] * l0
    }
    for (i = 1; i <= f; i++) {
        r0 = refq(i, 0); e = 0
        for (k = kmin; k <= kmax; k++) { d = qm[k] / qm[0] - refq(i, k * l0) / r0; e += d * d }
        mis[i] = sqrt(e / (kmax - kmin + 1))
        rl = 0; dz = zz[i, 2] - zz[i, 1]
        for (j = 1; j <= nz[i]; j++) rl += (j == 1 || j == nz[i] ? 0.5 : 1) * q[i, zz[i, j]] * dz
        mid[i] = qm[0] / r0 - 1; ld[i] = load / rl - 1
        printf "%.6g %.4g %+.4f %+.4f\n", dl[i], mis[i], mid[i], ld[i]
        if (!best || mis[i] < mis[best]) best = i
    }
    # a parabola through the smallest misfit and its neighbours (deltas equally spaced)
    d = dl[best]; m = best
    if (best > 1 && best < f) {
        a = mis[best - 1]; c = mis[best + 1]; den = a - 2 * mis[best] + c
        if (den > 0) {
            t = 0.5 * (a - c) / den; d = dl[best] + t * (dl[best + 1] - dl[best])
            m = t < 0 ? best - 1 : best; if (t >= 0 && m == f) m = f - 1
        }
    }
    if (m >= f) m = f - 1
    t = (d - dl[m]) / (dl[m + 1] - dl[m])
    printf "# fit delta %.4g misfit %.4g midRow %+.4f load %+.4f\n", d, mis[best],
           (1 - t) * mid[m] + t * mid[m + 1], (1 - t) * ld[m] + t * ld[m + 1]
}
