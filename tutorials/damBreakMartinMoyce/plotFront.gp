# The surge front of the MPS run (./Allrun) and of the MPH run (./Allrun -mph, in mph/), each
# when it has run, against Martin & Moyce's two experiment series.
set terminal pngcairo size 800,560 font ",11"
set output "front.png"
set xlabel "T = t (2 g / a)^{1/2}"
set ylabel "Z = x_{front} / a"
set key top left
set grid
set xrange [0:3.5]
set yrange [1:4.2]
# the case's column (fluid region 0): width a, height n^2 a, and its l0 (lubDict: lubkit on
# PATH, as in the Allrun; nan where it cannot be read)
# (awk writes each number with a decimal point: gnuplot's real() refuses "1e-5")
num(key) = (_s = system(sprintf("lubDict system/particleGenDict.yaml %s 2>/dev/null | awk '{ printf \"%%.17e\", $1 }'", key)), _s eq "" ? NaN : real(_s))
a = num("fluid.0.max.0") - num("fluid.0.min.0")
n2 = (num("fluid.0.max.1") - num("fluid.0.min.1")) / a
l0 = num("l0")
caption = sprintf("Collapse of a water column (n^2 = %.3g): surge front", n2)
set title caption
mps_title = sprintf("lubFoam (MPS), a = %g m, l_0 = a/%.3g", a, a / l0)
mph_title = sprintf("lubFoam (MPH), a = %g m, l_0 = a/%.3g", a, a / l0)
has(f) = system(sprintf("test -f '%s' && echo 1 || echo 0", f)) eq "1"
mps = "postProcessing/probe/frontZT.dat"
mph = "mph/postProcessing/probe/frontZT.dat"
# each front that has run (a plot command built as a string: a missing file is left out)
cmd = "plot "
if (has(mps)) cmd = cmd . sprintf("'%s' using 1:2 with lines lw 2 title '%s', ", mps, mps_title)
if (has(mph)) cmd = cmd . sprintf("'%s' using 1:2 with lines lw 2 dt 2 title '%s', ", mph, mph_title)
eval(cmd . "'martinMoyce1952.dat' using ($3 == 1.125 ? $1 : 1/0):2 with points pt 7 title 'Martin and Moyce, a = 1.125 in', " . \
     "'martinMoyce1952.dat' using ($3 == 2.25 ? $1 : 1/0):2 with points pt 5 title 'Martin and Moyce, a = 2.25 in'")
