# Dimensionless pressure P(X) of the thesis wedge (T-38, T-39; thesis Figure 7).
# Run from the case folder after reynoldsRef -dimensionless:  gnuplot plotPressure.gp
# (with the MPS wall pressure when ./Allrun -full has written it)
# p.dat columns: 1 x, 2 p, 3 h, 4 X, 5 P, 6 H.
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
# The case's own values for the title and the legends: its dictionaries, read with lubDict
# (lubkit on PATH, as in the Allrun); nan where they cannot be read
# (awk writes each number with a decimal point: gnuplot's real() refuses "1e-5")
num(file, key) = (_s = system(sprintf("lubDict %s %s 2>/dev/null | awk '{ printf \"%%.17e\", $1 }'", file, key)), _s eq "" ? NaN : real(_s))
gen = "system/particleGenDict.yaml"
R = num(gen, "walls.cylinder.radius")
h0 = num(gen, "walls.cylinder.lowestPoint.1") - num(gen, "walls.lowerWall.point.1")
U1 = num("constant/models.yaml", "movingWalls.lowerWall.velocity.0")
t0 = num("system/controlDict.yaml", "functions.wallPressure.timeStart")
t1 = num("system/controlDict.yaml", "functions.wallPressure.timeEnd")
rho = num("constant/transportProperties.yaml", "rho")
nu = num("constant/transportProperties.yaml", "nu")
caption = sprintf("Rigid wedge: cylinder R = %g m over a plane at U_1 = %g m/s, h_0 = %g {/Symbol m}m", R, U1, h0 * 1e6)
set title caption
set xlabel "X = x / sqrt(R h_0)"
set ylabel "P = h_0^{3/2} p / ({/Symbol r n} U_1 sqrt(R))"
set xrange [-6:2]
set yrange [0:*]
set grid
set key top left
# Martin's exit (T-37): X = 0.475 sqrt(2)
set arrow from 0.475*sqrt(2), graph 0 to 0.475*sqrt(2), graph 1 nohead dashtype 2 lc rgb "gray40"
set label " Martin exit (T-37)" at 0.475*sqrt(2), graph 0.70 left tc rgb "gray40"
# MPS: x and p of the wallPressure function object made dimensionless with the scales of
# reynoldsRef (T-38, T-39): X = x / sqrt(R h0), P = h0^1.5 p / (rho nu U1 sqrt(R))
sx = 1 / sqrt(R * h0)
sp = h0**1.5 / (rho * nu * U1 * sqrt(R))
win = sprintf("%g-%g ms", t0 * 1e3, t1 * 1e3)
# the table of the latest start time: a restarted run continues the average there
# (Allrun passes it with -e "mps = '...'")
if (!exists("mps")) mps = "postProcessing/wallPressure/0/p.dat"
# Reynolds from the inlet meniscus the MPS pool reached (Allrun -full: probe film, then
# reynoldsRef -inlet), the reference the run is judged against
men = "postProcessing/reynoldsRef/meniscus.dat"
if (system("test -s " . mps . " && echo 1 || echo 0") + 0) {
    if (system("test -s " . men . " && echo 1 || echo 0") + 0) {
        plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
             title "Reynolds equation, inlet of reynoldsRefDict", \
             men using 4:5 with lines lw 2 dt 2 lc rgb "blue" \
             title "Reynolds equation, inlet at the MPS meniscus (".win.")", \
             mps using ($1 * sx):($2 * sp) with points pt 7 ps 0.5 lc rgb "red" \
             title "MPS (lubFoam), cylinder wall, mean over ".win
    } else {
        plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
             title "Reynolds equation (reynoldsRef)", \
             mps using ($1 * sx):($2 * sp) with points pt 7 ps 0.5 lc rgb "red" \
             title "MPS (lubFoam), cylinder wall, mean over ".win
    }
} else {
    plot "postProcessing/reynoldsRef/0/p.dat" using 4:5 with lines lw 2 lc rgb "black" \
         title "Reynolds equation (reynoldsRef)"
}
