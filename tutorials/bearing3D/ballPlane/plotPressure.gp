# The ball over a plane: the MPS wall pressure at the mid-plane (time-averaged, function
# object wallPressure on the ball's particles within l0/2 of z = 0) against the mid-plane of
# the Reynolds equation over the contact's area, and the reference's pressure map.  Run from
# the case folder after Allrun:  gnuplot plotPressure.gp
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
R = num(gen, "walls.ball.radius")
h0 = num(gen, "walls.ball.centre.1") - R - num(gen, "walls.lowerWall.point.1")
U1 = num("constant/models.yaml", "movingWalls.lowerWall.velocity.0")
t0 = num("system/controlDict.yaml", "functions.wallPressure.timeStart")
t1 = num("system/controlDict.yaml", "functions.wallPressure.timeEnd")
l0 = num(gen, "l0")
set title sprintf("Ball R = %g mm over a plane at U_1 = %g m/s, h_0 = %g {/Symbol m}m, l_0 = h_0/%.3g: mid-plane z = 0", R * 1e3, U1, h0 * 1e6, h0 / l0)
set xlabel "x [mm]"
set ylabel "p [kPa]"
set xrange [-1:0.6]
set yrange [0:*]
set grid
set key top right
plot "postProcessing/reynoldsRef/0/p.dat" using ($1*1e3):($2*1e-3) with lines lw 2 \
         lc rgb "black" title "Reynolds over the area, z = 0", \
     pwall using ($1*1e3):($2*1e-3) with points pt 7 ps 0.6 \
         lc rgb "red" title sprintf("MPS, |z| < l_0/2, mean %g-%g ms", t0 * 1e3, t1 * 1e3)

set output "pressureMap.png"
set title sprintf("Ball R = %g mm, h_0 = %g {/Symbol m}m: the Reynolds pressure over the area [kPa]", R * 1e3, h0 * 1e6)
set xlabel "x [mm]"
set ylabel "z [mm]"
set view map
set size ratio -1
unset key
set xrange [*:*]
set yrange [*:*]
set pm3d map
splot "postProcessing/reynoldsRef/0/p2d.dat" using ($1*1e3):($2*1e3):($3*1e-3) with pm3d
