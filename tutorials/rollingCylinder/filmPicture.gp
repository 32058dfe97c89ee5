# The oil around the roller at a few times, one panel each, in the roller's frame (x - x_c,
# mm; the panels share the scale of both axes): the oil coloured by its speed, the roller's
# and the plate's wall particles dark, their dummy particles light.  Run by Allrun:
#
#     gnuplot -e "files = 'A B C'; xcs = 'xA xB xC'; titles = '\"t = ..\" \"..\" \"..\"'" filmPicture.gp
#
# files: tables of 'probe particles -field U' ('# x y kind patch Ux Uy'), one per panel;
# xcs: the roller's centre x [m] at each; titles: one per panel, each in double quotes; out:
# the PNG (default filmPicture.png); umax: the top of the colour scale [m/s] (default 0.5).
if (!exists("out")) out = "filmPicture.png"
if (!exists("umax")) umax = 0.5
n = words(files)
set terminal pngcairo size 980, 300 * n + 60 font ",11"
set output out
set multiplot layout n, 1 margins 0.08, 0.85, 0.08, 0.95 spacing 0, 0.09
set xrange [-15:30]
set yrange [-0.75:12]
set size ratio -1
set ylabel "y [mm]"
set cbrange [0:umax]
set palette defined (0 "#3060c0", 0.5 "#40c0a0", 1 "#f0c020")
set cblabel "oil speed [m/s]"
set key off
do for [i = 1:n] {
    xc = real(word(xcs, i))
    set title word(titles, i)
    if (i == n) { set xlabel "x - x_c [mm] (the roller's centre x_c; it rolls towards +x)" } else { unset xlabel }
    if (i == 1) { set colorbox user origin 0.89, 0.25 size 0.02, 0.5 } else { unset colorbox }
    f = word(files, i)
    plot f using ($3 == 2 ? 1e3 * ($1 - xc) : 1/0):(1e3 * $2) with points pt 7 ps 0.35 lc rgb "#c8c8c8", \
         f using ($3 == 1 ? 1e3 * ($1 - xc) : 1/0):(1e3 * $2) with points pt 7 ps 0.45 lc rgb "#404040", \
         f using ($3 == 0 ? 1e3 * ($1 - xc) : 1/0):(1e3 * $2):(sqrt($5 * $5 + $6 * $6)) with points pt 7 ps 0.55 lc palette
}
unset multiplot
