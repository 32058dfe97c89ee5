# The MPH film's pressure (P + pCohesive at mid-film, time-averaged) against the Reynolds
# equation from the MPH inlet meniscus with the Reynolds condition, with full Sommerfeld and
# with full Sommerfeld cut at the MPH film's end (givenExit).  Run from the case folder
# after Allrun:  gnuplot plotPressure.gp
# The title and the legend give the case's values (its dictionaries), not the tutorial's.
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
# the case's own values, read with lubDict (lubkit on PATH, as in the Allrun); nan where
# they cannot be read (awk writes each number with a decimal point: gnuplot's real()
# refuses "1e-5")
num(file, key) = (_s = system(sprintf("lubDict %s %s 2>/dev/null | awk '{ printf \"%%.17e\", $1 }'", file, key)), _s eq "" ? NaN : real(_s))
gen = "system/particleGenDict.yaml"
R = num(gen, "walls.arc.radius")
h0 = num(gen, "walls.arc.lowestPoint.1") - num(gen, "walls.lowerWall.point.1")
U1 = num("constant/models.yaml", "movingWalls.lowerWall.velocity.0")
sigma = num("constant/models.yaml", "surfaceTension.sigma")
t1 = num("system/controlDict.yaml", "endTime")
l0 = num(gen, "l0")
caption = sprintf("Arc bearing, MPH: R = %g mm over a plane at U = %g m/s, h_0 = %g {/Symbol m}m, l_0 = h_0/%.3g, {/Symbol s} = %g N/m", R * 1e3, U1, h0 * 1e6, h0 / l0, sigma)
set title caption
mph_title = sprintf("MPH, P + p_{coh} at mid-film, mean %g-%g ms", t1 / 2 * 1e3, t1 * 1e3)
set xlabel "x [mm]"
set ylabel "p [Pa]"
set grid
set key bottom left Left reverse
set xzeroaxis lt -1
plot "postProcessing/reynoldsRef/reynolds.dat" using ($1*1e3):2 with lines lw 2 lc rgb "black" \
         title "Reynolds condition (no tension)", \
     "postProcessing/reynoldsRef/fullSommerfeld.dat" using ($1*1e3):2 with lines lw 2 dt 2 \
         lc rgb "blue" title "full Sommerfeld", \
     "postProcessing/reynoldsRef/givenExit.dat" using ($1*1e3):2 with lines lw 1 dt 3 \
         lc rgb "dark-green" title "full Sommerfeld to the MPH film's end", \
     "postProcessing/probe/p.dat" using ($1*1e3):2 with linespoints pt 7 ps 0.6 \
         lc rgb "red" title mph_title
