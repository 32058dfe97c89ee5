/* Unit tests of src/particles/particles.c: structure-of-arrays storage. */
#include <stdint.h>
#include <stdlib.h>

#include "particles/particles.h"
#include "test.h"

static void test_init(void)
{
    lub_particles P;
    lub_particles_init(&P, 2, 10);
    CHECK(P.dim == 2);
    CHECK(P.n == 0);
    CHECK(P.cap >= 10);
    CHECK(P.nlevels == 1);
    CHECK(P.npatches == 0 && P.nextra == 0);
    lub_particles_free(&P);
    CHECK(P.n == 0 && P.cap == 0 && P.x[0] == NULL && P.nextra == 0);

    lub_particles_init(&P, 3, 0); /* capacity 0 is allowed: add grows */
    double x[3] = {1, 2, 3};
    CHECK(lub_particles_add(&P, x, LUB_FLUID, 0, 0) == 0);
    CHECK(P.n == 1 && P.cap >= 1);
    lub_particles_free(&P);
}

static void test_add_2d(void)
{
    lub_particles P;
    lub_particles_init(&P, 2, 4);
    int w = lub_particles_patch(&P, "lowerWall");
    /* 2-D: only x[0], x[1] are read (a 2-element array must do), z is set to 0. */
    double xy[2] = {0.25, -1.5};
    size_t i = lub_particles_add(&P, xy, LUB_WALL, w, 0);
    CHECK(i == 0);
    CHECK(P.x[0][0] == 0.25 && P.x[1][0] == -1.5 && P.x[2][0] == 0.0);
    CHECK(P.u[0][0] == 0.0 && P.u[1][0] == 0.0 && P.u[2][0] == 0.0 && P.p[0] == 0.0);
    CHECK(P.kind[0] == LUB_WALL && P.patch[0] == w && P.level[0] == 0);
    CHECK(P.id[0] == 0);
    double xy2[2] = {3, 4};
    CHECK(lub_particles_add(&P, xy2, LUB_FLUID, 0, 0) == 1);
    CHECK(P.id[1] == 1 && P.kind[1] == LUB_FLUID);
    lub_particles_free(&P);
}

/* Growth by doubling keeps every value; capacity stays within twice the count. */
static void test_growth(void)
{
    lub_particles P;
    lub_particles_init(&P, 3, 1);
    double *pm = lub_particles_extra(&P, "pMean");
    (void)pm;
    const size_t n = 1000;
    size_t reallocs = 0, last_cap = P.cap;
    for (size_t i = 0; i < n; i++) {
        double x[3] = {(double)i, 2.0 * (double)i, -(double)i};
        size_t k = lub_particles_add(&P, x, (int)(i % 3), 0, (int)(i % 2));
        P.p[k] = 0.5 * (double)i;
        P.u[1][k] = (double)i + 0.25;
        lub_particles_find_extra(&P, "pMean")[k] = 3.0 * (double)i;
        if (P.cap != last_cap) reallocs++, last_cap = P.cap;
    }
    CHECK(P.n == n);
    CHECK(P.cap >= n && P.cap <= 2 * n);
    CHECK(reallocs <= 11); /* doubling from 1: log2(1000) < 10 */
    int ok = 1;
    double *e = lub_particles_find_extra(&P, "pMean");
    for (size_t i = 0; i < n; i++) {
        ok &= P.x[0][i] == (double)i && P.x[1][i] == 2.0 * (double)i && P.x[2][i] == -(double)i;
        ok &= P.p[i] == 0.5 * (double)i && P.u[1][i] == (double)i + 0.25 && P.u[0][i] == 0.0;
        ok &= P.kind[i] == i % 3 && P.level[i] == i % 2 && P.id[i] == i;
        ok &= e[i] == 3.0 * (double)i;
    }
    CHECK(ok);
    lub_particles_free(&P);
}

/* After an explicit reserve, adding up to the capacity never moves an array (the solver's
 * time loop must not allocate). */
static void test_reserve_no_realloc(void)
{
    lub_particles P;
    lub_particles_init(&P, 2, 4);
    double *e = lub_particles_extra(&P, "pnd");
    double x[2] = {1, 1};
    lub_particles_add(&P, x, LUB_FLUID, 0, 0);
    P.p[0] = 42.0;
    e[0] = 7.0;
    lub_particles_reserve(&P, 5000);
    CHECK(P.cap == 5000);
    /* the extra field grew with the rest, old values kept, new tail zero */
    e = lub_particles_find_extra(&P, "pnd");
    CHECK(e[0] == 7.0 && P.p[0] == 42.0);
    int zero = 1;
    for (size_t i = 1; i < P.cap; i++) zero &= e[i] == 0.0 && P.p[i] == 0.0;
    CHECK(zero);

    double *px = P.x[0], *pu = P.u[2], *pp = P.p;
    uint8_t *pk = P.kind;
    uint64_t *pid = P.id;
    for (int i = 1; i < 5000; i++) lub_particles_add(&P, x, LUB_FLUID, 0, 0);
    CHECK(P.n == 5000 && P.cap == 5000);
    CHECK(P.x[0] == px && P.u[2] == pu && P.p == pp && P.kind == pk && P.id == pid);
    CHECK(lub_particles_find_extra(&P, "pnd") == e);

    /* reserve never shrinks */
    lub_particles_reserve(&P, 10);
    CHECK(P.cap == 5000 && P.x[0] == px);
    lub_particles_free(&P);
}

static void test_patches(void)
{
    lub_particles P;
    lub_particles_init(&P, 2, 4);
    CHECK(lub_particles_find_patch(&P, "cylinder") == -1);
    CHECK(lub_particles_patch(&P, "lowerWall") == 0);
    CHECK(lub_particles_patch(&P, "cylinder") == 1);
    CHECK(lub_particles_patch(&P, "lowerWall") == 0);
    CHECK(P.npatches == 2);
    CHECK(lub_particles_find_patch(&P, "cylinder") == 1);
    CHECK_STR(P.patch_names[1], "cylinder");

    char long_name[LUB_NAME_MAX + 1];
    memset(long_name, 'a', LUB_NAME_MAX);
    long_name[LUB_NAME_MAX] = '\0';
    CHECK_FATAL(lub_particles_patch(&P, long_name), "too long");
    CHECK_FATAL(lub_particles_patch(&P, ""), "empty patch name");
    CHECK_FATAL(lub_particles_patch(&P, "a/b"), "'/'");
    CHECK(P.npatches == 2);

    char name[32];
    for (int k = 2; k < LUB_MAX_PATCHES; k++) {
        snprintf(name, sizeof name, "wall%d", k);
        CHECK(lub_particles_patch(&P, name) == k);
    }
    CHECK_FATAL(lub_particles_patch(&P, "oneTooMany"), "too many patches");
    CHECK(P.npatches == LUB_MAX_PATCHES);
    lub_particles_free(&P);
}

static void test_extra(void)
{
    lub_particles P;
    lub_particles_init(&P, 2, 8);
    double x[2] = {0, 0};
    for (int i = 0; i < 5; i++) lub_particles_add(&P, x, LUB_FLUID, 0, 0);
    CHECK(lub_particles_find_extra(&P, "pMean") == NULL);
    double *a = lub_particles_extra(&P, "pMean");
    CHECK(a != NULL && P.nextra == 1);
    int zero = 1;
    for (size_t i = 0; i < P.cap; i++) zero &= a[i] == 0.0;
    CHECK(zero);
    CHECK(lub_particles_extra(&P, "pMean") == a); /* found, not added twice */
    CHECK(lub_particles_find_extra(&P, "pMean") == a);
    CHECK(P.nextra == 1);
    CHECK_STR(P.extra[0].name, "pMean");
    /* a particle added later starts with extra value 0 */
    a[0] = 5.0;
    lub_particles_add(&P, x, LUB_FLUID, 0, 0);
    CHECK(a[5] == 0.0 && a[0] == 5.0);

    CHECK_FATAL(lub_particles_extra(&P, "position"), "standard particle field");
    CHECK_FATAL(lub_particles_extra(&P, "id"), "standard particle field");
    CHECK_FATAL(lub_particles_extra(&P, "a<b"), "'<'");
    char name[32];
    for (int k = 1; k < LUB_MAX_EXTRA; k++) {
        snprintf(name, sizeof name, "f%d", k);
        CHECK(lub_particles_extra(&P, name) != NULL);
    }
    CHECK(P.nextra == LUB_MAX_EXTRA);
    CHECK_FATAL(lub_particles_extra(&P, "oneTooMany"), "too many extra");
    lub_particles_free(&P);
}

int main(void)
{
    RUN(test_init);
    RUN(test_add_2d);
    RUN(test_growth);
    RUN(test_reserve_no_realloc);
    RUN(test_patches);
    RUN(test_extra);
    return test_summary();
}
