# MPS wall pressure (time-averaged, function object wallPressure) against the Reynolds
# equation.  Run from the case folder after Allrun:  gnuplot plotPressure.gp
# The title and the legend give the case's values (its dictionaries), not the tutorial's:
# ../optStudy's runs at other Nr and a1 are titled with theirs.
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
l0 = num(gen, "levels.0.l0")
a1 = num(gen, "levels.0.region.0")
a2 = num(gen, "levels.0.region.1")
lc = num(gen, "levels.1.l0")
caption = sprintf("Reduced wedge, two levels (OPT): l_0 = h_0/%.3g in [%g, %g] mm, %.3g l_0 elsewhere; U_1 = %g m/s, R = %g m", h0 / l0, a1 * 1e3, a2 * 1e3, lc / l0, U1, R)
set title caption
mps_title = sprintf("MPS, mean %g-%g ms", t0 * 1e3, t1 * 1e3)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-1.5:1]
set yrange [0:*]
set grid
set key top right
plot "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 lc rgb "black" \
         title "Reynolds, inlet at MPS meniscus", \
     "postProcessing/wallPressure/0/p.dat" using ($1*1e3):($2*1e-3) with points pt 7 ps 0.6 \
         lc rgb "red" title mps_title
