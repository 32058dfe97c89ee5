/* lubkit MPS: the reference values of a particle lattice (see weight.h). */
#include "particles/weight.h"

#include <math.h>

#include "core/error.h"

void lub_mps_reference(int dim, double l0, double re, double *n0, double *lambda0)
{
    if ((dim != 2 && dim != 3) || !(l0 > 0) || !(re > 0))
        lub_bug("reference PND: dim %d, l0 %g, re %g", dim, l0, re);
    /* (T-4, T-5): every lattice node within re of the centre node */
    const int m = (int)ceil(re / l0) + 1, mz = dim == 3 ? m : 0;
    double sw = 0.0, sr2w = 0.0;
    for (int c = -mz; c <= mz; c++)
        for (int b = -m; b <= m; b++)
            for (int a = -m; a <= m; a++) {
                if (a == 0 && b == 0 && c == 0) continue;
                double r2 = l0 * l0 * ((double)a * a + (double)b * b + (double)c * c);
                double w = lub_mps_weight(sqrt(r2), re);
                sw += w;
                sr2w += r2 * w;
            }
    *n0 = sw;
    *lambda0 = sr2w / sw;
}
