/*
 * energy_tables.c - writes src/render/energy_tables.inc, the tables of the
 * single-scattering albedo that energy compensation reads (render/energy.h),
 * computed by render/energy_gen.h from the lobes' own code:
 *
 *     build/tests/energy_tables > src/render/energy_tables.inc
 *
 * tests/render/test_energy.c recomputes entries the same way and compares,
 * so a change to a lobe that changes its albedo fails there until the
 * tables are written again. Takes about a minute.
 */
#include "render/energy_gen.h"

#include <stdio.h>

static void row(const double *v, int n, const char *indent, bool last)
{
    printf("%s{", indent);
    for (int i = 0; i < n; i++) printf("%s%.7ff", i ? ", " : "", v[i]);
    printf("}%s \\\n", last ? "" : ",");
}

int main(void)
{
    static double e[2][PK_EN_ALPHA][PK_EN_MU], avg[2][PK_EN_ALPHA];
    for (int d = 0; d < 2; d++)
        for (int a = 0; a < PK_EN_ALPHA; a++) {
            for (int m = 0; m < PK_EN_MU; m++)
                e[d][a][m] = energy_gen_conductor(d == 1, energy_gen_node(a, PK_EN_ALPHA), energy_gen_mu(m, PK_EN_MU),
                                                  ENERGY_GEN_N_CONDUCTOR);
            avg[d][a] = energy_gen_avg(e[d][a], PK_EN_MU);
        }
    printf("/* energy_tables.inc - written by bench/energy_tables.c (render/energy_gen.h); do not edit.\n"
           " * render/energy.h says what the numbers are. */\n\n");
    printf("/* E(mu, alpha) [GGX, Beckmann][alpha][mu] */\n#define PK_ENERGY_E_INIT \\\n{ \\\n");
    for (int d = 0; d < 2; d++) {
        printf("  { \\\n");
        for (int a = 0; a < PK_EN_ALPHA; a++) row(e[d][a], PK_EN_MU, "    ", a == PK_EN_ALPHA - 1);
        printf("  }%s \\\n", d ? "" : ",");
    }
    printf("}\n\n/* E_avg(alpha) [GGX, Beckmann][alpha] */\n#define PK_ENERGY_EAVG_INIT \\\n{ \\\n");
    for (int d = 0; d < 2; d++) row(avg[d], PK_EN_ALPHA, "  ", d == 1);
    printf("}\n\n/* E_d(mu, alpha, n) [GGX, Beckmann][from outside, from inside][n][alpha][mu] */\n"
           "#define PK_ENERGY_D_INIT \\\n{ \\\n");
    for (int d = 0; d < 2; d++) {
        printf("  { \\\n");
        for (int s = 0; s < 2; s++) {
            printf("    { \\\n");
            for (int k = 0; k < PK_EN_DETA; k++) {
                printf("      { \\\n");
                for (int a = 0; a < PK_EN_DALPHA; a++) {
                    double v[PK_EN_DMU];
                    for (int m = 0; m < PK_EN_DMU; m++)
                        v[m] = energy_gen_dielectric(d == 1, s == 1, energy_gen_eta(k), energy_gen_node(a, PK_EN_DALPHA),
                                                     energy_gen_mu(m, PK_EN_DMU), ENERGY_GEN_N_DIELECTRIC);
                    row(v, PK_EN_DMU, "        ", a == PK_EN_DALPHA - 1);
                }
                printf("      }%s \\\n", k == PK_EN_DETA - 1 ? "" : ",");
            }
            printf("    }%s \\\n", s ? "" : ",");
        }
        printf("  }%s \\\n", d ? "" : ",");
    }
    printf("}\n");
    return 0;
}
