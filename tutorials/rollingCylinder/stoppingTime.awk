# When the roller stops, from its table postProcessing/rigidBodies/0/<body>.dat ('# t[s] x[m]
# y[m] angle[rad] Vx[m/s] ...', the columns found by name):
#
#     awk -v vStop=0.01 -v from=0.05 -f stoppingTime.awk TABLE
#
# The roller has stopped when its speed along the plate Vx first falls to vStop [m/s]: tStop
# and xStop interpolated linearly between the two rows around it.  Over [from, t1], t1 =
# tStop or, if Vx stays above vStop, the table's last time tEnd (from [s] skips the roller's
# approach on the dry plate, where nothing brakes it):
#   decelMean  (V(from) - V(t1)) / (t1 - from)
#   decelFit   the least-squares slope of Vx against t, negated
#   decayTime  tau of V ~ exp(-t/tau), the least-squares slope of ln Vx against t over the
#              second half of [from, t1], -1/slope: a film's viscous resistance grows with
#              the speed, so that the roller slows about exponentially (nan if Vx <= 0 there)
# A roller still moving at tEnd gets two projections, neither a result:
#   tStopProjected     at the fitted deceleration held constant: tEnd + (VEnd - vStop) / a
#                      (too early when the resistance falls with the speed)
#   tStopProjectedExp  on the exponential of the last half: tEnd + tau ln(VEnd / vStop)
# Prints one table row under its header:
#
#     # stopped vStop[m/s] from[s] tEnd[s] VFrom[m/s] VEnd[m/s] tStop[s] xStop[m]
#       decelMean[m/s^2] decelFit[m/s^2] decayTime[s] tStopProjected[s] tStopProjectedExp[s]
#
# stopped = 1 with tStop, xStop (the projections nan); 0 with tStop, xStop nan, and a
# projection nan when its deceleration (or tau) is not positive.  tEnd, VEnd: the last row.
# Exit 1 with a message when the table has no Vx column, or fewer than 6 rows in
# [from, t1] (each half needs more rows than unknowns).
function fail(msg) {
    printf "stoppingTime.awk: %s: %s\n", FILENAME, msg > "/dev/stderr"
    bad = 1
    exit 1
}
function keep(tt, vv) { nf++; T[nf] = tt; V[nf] = vv }
# least-squares slope of V against T over rows i0..i1 (lg: of ln V); nan if a V <= 0 (lg)
function slope(i0, i1, lg,   i, n, st, sy, stt, sty, y) {
    for (i = i0; i <= i1; i++) {
        y = V[i]
        if (lg) { if (y <= 0) return "nan"; y = log(y) }
        n++; st += T[i]; sy += y; stt += T[i] * T[i]; sty += T[i] * y
    }
    return (n * sty - st * sy) / (n * stt - st * st)
}
function num(v) { return v == "nan" ? "nan" : sprintf("%.6g", v) }
BEGIN {
    if (vStop == "") vStop = 0.01
    if (from == "") from = 0.05
    stopped = 0
}
/^#/ && !cols {
    for (i = 2; i <= NF; i++) { nm = $i; sub(/\[.*/, "", nm); col[nm] = i - 1 }
    if (!("t" in col) || !("x" in col) || !("Vx" in col)) fail("expected columns t, x, Vx in the header, found '" $0 "'")
    cols = 1
    next
}
/^#/ || NF == 0 { next }
{
    if (!cols) fail("no header line ('# t[s] x[m] ... Vx[m/s] ...') before the first row")
    t = $(col["t"]); x = $(col["x"]); v = $(col["Vx"])
    tEnd = t; vEnd = v
    if (stopped) next
    if (n && v <= vStop && pv > vStop) {
        # the crossing, between the previous row and this one
        f = (pv - vStop) / (pv - v)
        tStop = pt + f * (t - pt); xStop = px + f * (x - px)
        stopped = 1
        if (tStop >= from) keep(tStop, vStop)
        t1 = tStop; v1 = vStop
        next
    }
    n++
    if (t >= from) {
        if (!nf) vFrom = v
        keep(t, v)
    }
    pt = t; px = x; pv = v
    t1 = t; v1 = v
}
END {
    if (bad) exit 1
    if (!cols) fail("empty table")
    if (nf < 6) fail(sprintf("%d rows in [from, t1] = [%g, %g] s: the fits need at least 6", nf, from, t1))
    a = -slope(1, nf, 0)
    # the second half of [from, t1]: the rows from its middle on
    for (h = 1; h < nf && T[h] < (from + t1) / 2; h++) ;
    if (nf - h < 2) h = nf - 2
    k = slope(h, nf, 1)
    tau = (k == "nan" || k >= 0) ? "nan" : -1 / k
    mean = (vFrom - v1) / (t1 - from)
    proj = projExp = "nan"
    if (!stopped && a > 0) proj = tEnd + (vEnd - vStop) / a
    if (!stopped && tau != "nan" && vEnd > 0) projExp = tEnd + tau * log(vEnd / vStop)
    print "# stopped vStop[m/s] from[s] tEnd[s] VFrom[m/s] VEnd[m/s] tStop[s] xStop[m] decelMean[m/s^2] decelFit[m/s^2] decayTime[s] tStopProjected[s] tStopProjectedExp[s]"
    printf "%d %g %g %.6g %.6g %.6g %s %s %.6g %.6g %s %s %s\n", stopped, vStop, from, tEnd, vFrom, vEnd,
        stopped ? num(tStop) : "nan", stopped ? num(xStop) : "nan", mean, a, num(tau), num(proj), num(projExp)
}
