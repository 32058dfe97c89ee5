# Soft EHL: dimensionless pressure P(X) and film H(X) of the MPS run against the Reynolds-EHL
# reference (T-54..T-58: X = x/b, P = p/p_H, H = h R/b^2), and the load history of the
# elastic wall.  Run from the case folder after Allrun (which runs it):  gnuplot plotEHL.gp
# (ehl.png).  The title, the scales b and p_H and the averaging window are the case's own
# (its dictionaries, read with lubDict: lubkit on PATH, as in the Allrun).
#
# Files (Allrun writes them; the MPS ones are left out when absent or without rows):
#   postProcessing/reynoldsRef/0/p.dat          # x p h X P H
#   postProcessing/wallPressure/0/p.dat         # x[m] p[Pa] n  (lubFoam function object, time mean)
#   postProcessing/probe/wallShape.dat          # x y v h X H    (probe wallShape)
#   postProcessing/probe/film.dat               # x h surface bottom contact n X H filled full
#                                               #   (probe film; full: the gap full of oil)
#   postProcessing/elasticWall/0/elasticWall.dat  # t h0 centre load loadTarget ... (lubFoam)
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,1150 enhanced font ",11"
} else {
    set terminal png size 900,1150
}
set output "ehl.png"

# the case's values (nan when lubDict cannot read them)
# (awk writes each number with a decimal point: gnuplot's real() refuses "1e-5")
num(file, key) = (_s = system(sprintf("lubDict %s %s 2>/dev/null | awk '{ printf \"%%.17e\", $1 }'", file, key)), _s eq "" ? NaN : real(_s))
gen = "system/particleGenDict.yaml"
models = "constant/models.yaml"
R = num(gen, "walls.cylinder.radius")
l0 = num(gen, "l0")
if (l0 != l0) l0 = num(gen, "levels.0.l0")  # multi-resolution: the finest level
E = num(models, "elasticWall.E")
W = num(models, "elasticWall.load")
U1 = num(models, "movingWalls.lowerWall.velocity.0")
t0 = num("system/controlDict.yaml", "functions.wallPressure.timeStart")
t1 = num("system/controlDict.yaml", "functions.wallPressure.timeEnd")
# Hertz line contact (T-54, T-55): the half-width b and the pressure p_H of the load W
if (!exists("b")) b = sqrt(8 * W * R / (pi * E))
if (!exists("pH")) pH = 2 * W / (pi * b)
# the tables of the latest start time: a restarted run continues the average there (the
# thesis-scale Allruns pass them with -e "pw = '...'; ew = '...'")
if (!exists("pw")) pw = "postProcessing/wallPressure/0/p.dat"
if (!exists("ew")) ew = "postProcessing/elasticWall/0/elasticWall.dat"
ref = "postProcessing/reynoldsRef/0/p.dat"
ws = "postProcessing/probe/wallShape.dat"
fm = "postProcessing/probe/film.dat"
# the outlet meniscus of probe film: where the oil stops filling the gap
_x = system("sed -n 's/^# outletMeniscus x = .* X = \\([^ ]*\\) .*/\\1/p' " . fm . " 2>/dev/null")
xout = _x eq "" ? NaN : real(_x)
has(f) = system("grep -qsv '^#' " . f . " && echo 1 || echo 0") + 0

caption = sprintf("Soft EHL: cylinder R = %g m, E' = %g Pa, W = %g N/m, U_1 = %g m/s, l_0 = %g {/Symbol m}m (b = %.3g {/Symbol m}m, p_H = %.4g MPa)", R, E, W, U1, l0 * 1e6, b * 1e6, pH * 1e-6)
mps_title = sprintf("MPS wall pressure (lubFoam), mean over %g-%g ms", t0 * 1e3, t1 * 1e3)
set multiplot layout 3,1 title caption
set grid
set key bottom center

set title "Pressure on the elastic cylinder"
set xlabel "X = x / b"
set ylabel "P = p / p_H"
set yrange [0:*]
if (has(pw)) {
    plot ref using 4:5 with lines lw 2 lc rgb "black" title "Reynolds-EHL (reynoldsRef)", \
         pw using ($1 / b):($2 / pH) with points pt 7 ps 0.5 lc rgb "red" \
         title mps_title
} else {
    plot ref using 4:5 with lines lw 2 lc rgb "black" title "Reynolds-EHL (reynoldsRef)"
}

set title "Film thickness"
set ylabel "H = h R / b^2"
# room above the film for the key
stats ref using 6 nooutput
set yrange [0:1.7 * STATS_max]
set key top left Left reverse
if (xout == xout) {
    set arrow 1 from xout, graph 0 to xout, graph 1 nohead dashtype 2 lc rgb "gray40"
    set label 1 "outlet meniscus (probe film) " at xout, graph 0.06 right tc rgb "gray40"
}
# probe film where the oil fills the gap (its column full: the fraction of the time folders
# with a full gap) is the film; past the outlet meniscus the film has split and h is the
# height of the oil left on the plate, not a film
if (has(ws)) {
    plot ref using 4:6 with lines lw 2 lc rgb "black" title "Reynolds-EHL", \
         ws using 5:6 with lines lw 1.5 lc rgb "red" title "MPS: elastic wall above the plane (probe wallShape)", \
         fm using 7:($10 >= 0.5 ? $8 : 1/0) with points pt 6 ps 0.5 lc rgb "blue" \
         title "MPS: oil film filling the gap (probe film)", \
         fm using 7:($10 < 0.5 ? $8 : 1/0) with points pt 8 ps 0.6 lc rgb "#2ca02c" \
         title "MPS: oil on the plate where the gap is not full (past the film's ends)"
} else {
    plot ref using 4:6 with lines lw 2 lc rgb "black" title "Reynolds-EHL"
}
unset arrow 1
unset label 1

set title "Load balance (T-51..T-53)"
set xlabel "t [ms]"
set ylabel "load [N/m]"
set yrange [0:*]
set key bottom right Right noreverse
if (has(ew)) {
    plot ew using ($1 * 1e3):8 with points pt 7 ps 0.3 lc rgb "#6baed6" \
         title "integral of the wall pressure of a single step", \
         ew using ($1 * 1e3):5 with lines lw 2 lc rgb "black" title "load W(t)", \
         ew using ($1 * 1e3):4 with lines lw 2 lc rgb "red" \
         title "integral of the running mean of the wall pressure (the balance)"
} else {
    unset key
    set label 1 "no MPS run yet" at graph 0.5, 0.5 center
    plot [0:1][0:1] 2 notitle
}
unset multiplot
