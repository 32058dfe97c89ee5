# The 2-D Reynolds equation over [xa, xb] x [-W/2, W/2] with p = 0 on the boundary (full
# Sommerfeld; with cav = 1 projected SOR: p >= 0, the Reynolds condition), the gap of a sphere (centre (0, cy, 0), radius R) over the plane y = 0,
# h = cy - sqrt(R^2 - x^2 - z^2), solved by SOR on the conservative five-point scheme: each
# node's balance of the fluxes h^3/(12 mu) grad p through its four faces (the gap at the face
# midpoints) against Um (h(x + dx/2) - h(x - dx/2)) dz.  Prints "x z p" of every node.
function gap(x, z) { return cy - sqrt(R * R - x * x - z * z) }
BEGIN {
    dx = (xb - xa) / nx; dz = w / nz; um = 0.5 * u1; c = 1 / (12 * mu)
    for (i = 1; i < nx; i++) for (j = 1; j < nz; j++) {
        x = xa + i * dx; z = -w / 2 + j * dz
        hl = gap(x - dx / 2, z); hr = gap(x + dx / 2, z)
        hs = gap(x, z - dz / 2); hn = gap(x, z + dz / 2)
        aw[i, j] = hl ^ 3 * c * dz / dx; ae[i, j] = hr ^ 3 * c * dz / dx
        as[i, j] = hs ^ 3 * c * dx / dz; an[i, j] = hn ^ 3 * c * dx / dz
        f[i, j] = um * (hr - hl) * dz
    }
    for (i = 0; i <= nx; i++) for (j = 0; j <= nz; j++) p[i, j] = 0
    for (it = 0; it < 20000; it++) {
        dmax = 0; pmax = 0
        for (i = 1; i < nx; i++) for (j = 1; j < nz; j++) {
            q = (aw[i, j] * p[i - 1, j] + ae[i, j] * p[i + 1, j] + as[i, j] * p[i, j - 1] + \
                 an[i, j] * p[i, j + 1] - f[i, j]) / (aw[i, j] + ae[i, j] + as[i, j] + an[i, j])
            d = omega * (q - p[i, j]); if (cav && p[i, j] + d < 0) d = -p[i, j]
            p[i, j] += d
            if (d < 0) d = -d
            if (d > dmax) dmax = d
            if (p[i, j] > pmax) pmax = p[i, j]
        }
        if (dmax < 1e-14 * pmax) break
    }
    for (i = 0; i <= nx; i++) for (j = 0; j <= nz; j++)
        printf "%.17g %.17g %.17g\n", xa + i * dx, -w / 2 + j * dz, p[i, j]
    printf "# sweeps %d\n", it > "/dev/stderr"
}
