# The roller of finite width: the MPS wall pressure at the mid-plane (time-averaged, function
# object wallPressure on the row z = 0) against the finite-width Reynolds equation's
# mid-plane, and the infinitely wide (2-D) reference from the same inlet.  Run from the case
# folder after Allrun:  gnuplot plotPressure.gp
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 900,600 enhanced font ",11"
} else {
    set terminal png size 900,600
}
set output "pressure.png"
# the mid-plane table: Allrun gives the latest start's (gnuplot -e "pwall='...'")
if (!exists("pwall")) pwall = "postProcessing/wallPressure/0/p.dat"
# the case's own values (its dictionaries, read with lubDict; nan where they cannot be read)
num(file, key) = (_s = system(sprintf("lubDict %s %s 2>/dev/null | awk '{ printf \"%%.17e\", $1 }'", file, key)), _s eq "" ? NaN : real(_s))
gen = "system/particleGenDict.yaml"
R = num(gen, "walls.cylinder.radius")
W = num(gen, "walls.cylinder.length")
h0 = num(gen, "walls.cylinder.lowestPoint.1") - num(gen, "walls.lowerWall.point.1")
U1 = num("constant/models.yaml", "movingWalls.lowerWall.velocity.0")
t0 = num("system/controlDict.yaml", "functions.wallPressure.timeStart")
t1 = num("system/controlDict.yaml", "functions.wallPressure.timeEnd")
l0 = num(gen, "l0")
set title sprintf("Roller R = %g m, W = %g mm over a plane at U_1 = %g m/s, h_0 = %g {/Symbol m}m, l_0 = h_0/%.3g: mid-plane", R, W * 1e3, U1, h0 * 1e6, h0 / l0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-1.5:1]
set yrange [0:*]
set grid
set key top right
plot "postProcessing/reynoldsRef/0/pInfiniteWidth.dat" using ($1*1e3):($2*1e-3) with lines \
         lw 1 dt 2 lc rgb "gray40" title "Reynolds, infinitely wide", \
     "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 \
         lc rgb "black" title "Reynolds, width W, z = 0", \
     pwall using ($1*1e3):($2*1e-3) with points pt 7 ps 0.6 \
         lc rgb "red" title sprintf("MPS, z = 0, mean %g-%g ms", t0 * 1e3, t1 * 1e3)

# across the width at the x of the reference's mid-plane peak (Allrun writes both tables)
set output "pressureAcross.png"
set title sprintf("Roller W = %g mm, l_0 = h_0/%.3g: wall pressure across the width at the mid-plane peak's x", W * 1e3, h0 / l0)
set xlabel "z [mm]"
set xrange [-W * 500 - 0.05:W * 500 + 0.05]
set key bottom center
plot "postProcessing/reynoldsRef/0/pAcross.dat" using ($1*1e3):($2*1e-3) with lines lw 2 \
         lc rgb "black" title "Reynolds, width W", \
     "postProcessing/probe/pAcross.dat" using ($1*1e3):($2*1e-3) with linespoints pt 7 ps 0.6 \
         lc rgb "red" title sprintf("MPS wall rows, %g-%g ms (time folders)", t0 * 1e3, t1 * 1e3)
