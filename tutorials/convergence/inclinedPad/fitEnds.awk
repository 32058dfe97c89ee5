# The Reynolds equation with the pad's ends at pressures of their own, fitted to a wall
# pressure table ('# x p ...', as probe wallPressure -bin writes it):
#
#     p(x) = a_in (1 - F(x)) + a_out F(x) + b p_R(x)       over xa < x < xb
#
# p_R is the closed form of the inclined slider (p = 0 at both ends; h = h1 + (h0 - h1) x/L):
#     p_R = 6 mu U L/(h1 - h0) [1/h - 1/h1 - (h*/2)(1/h^2 - 1/h1^2)],  h* = 2 h0 h1/(h0 + h1)
# and F = int_0^x h^-3 / int_0^L h^-3 = (1/h^2 - 1/h1^2)/(1/h0^2 - 1/h1^2).  1 and F are the
# homogeneous solutions of (h^3 p')' = 6 mu U h' (the film carries no source of its own), so
# p_R + a_in (1 - F) + a_out F is the Reynolds pressure of the same film with p = a_in at
# the leading edge and a_out at the trailing edge: whatever the ends do, Reynolds holds
# inside the film, and b = 1 there.  Least squares over the rows with xa < x < xb (the
# normal equations, 3 x 3, by Cramer's rule).
#
#     awk -v mu=MU -v U=U -v L=L -v h0=H0 -v h1=H1 -v xa=XA -v xb=XB -f fitEnds.awk TABLE
#
# prints 'a_in a_out b n' (Pa, Pa, 1, rows used); exit 1 with a message when fewer than 4
# rows fall in the range (the fit needs more rows than unknowns).
function pR(x,   h) {
    h = h1 + (h0 - h1) * x / L
    return 6 * mu * U * L / (h1 - h0) * (1 / h - 1 / h1 - hs / 2 * (1 / h^2 - 1 / h1^2))
}
function F(x,   h) {
    h = h1 + (h0 - h1) * x / L
    return (1 / h^2 - 1 / h1^2) / (1 / h0^2 - 1 / h1^2)
}
function det3(a11, a12, a13, a21, a22, a23, a31, a32, a33) {
    return a11 * (a22 * a33 - a23 * a32) - a12 * (a21 * a33 - a23 * a31) + a13 * (a21 * a32 - a22 * a31)
}
BEGIN { hs = 2 * h0 * h1 / (h0 + h1) }
!/^#/ && NF >= 2 && $1 > xa && $1 < xb {
    # the basis at this row: u = 1 - F, v = F, w = p_R; the normal equations' sums
    v = F($1); u = 1 - v; w = pR($1)
    suu += u * u; suv += u * v; suw += u * w; svv += v * v; svw += v * w; sww += w * w
    sup += u * $2; svp += v * $2; swp += w * $2; n++
}
END {
    if (n < 4) { printf "fitEnds.awk: %d rows in %g < x < %g, need 4 or more\n", n, xa, xb > "/dev/stderr"; exit 1 }
    D = det3(suu, suv, suw, suv, svv, svw, suw, svw, sww)
    printf "%.17g %.17g %.17g %d\n", det3(sup, suv, suw, svp, svv, svw, swp, svw, sww) / D,
           det3(suu, sup, suw, suv, svp, svw, suw, swp, sww) / D,
           det3(suu, suv, sup, suv, svv, svp, suw, svw, swp) / D, n
}
