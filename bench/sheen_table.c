/*
 * sheen_table.c - writes src/render/sheen_table.inc, the directional albedo
 * of glTF's sheen lobe (render/sheen.h), integrated by render/sheen_gen.h:
 *
 *     build/tests/sheen_table > src/render/sheen_table.inc
 *
 * tests/unit/test_gltf_lobes.c recomputes entries the same way and compares.
 */
#include "render/sheen_gen.h"

#include <stdio.h>

int main(void)
{
    printf("/* sheen_table.inc - written by bench/sheen_table.c (render/sheen_gen.h); do not edit.\n"
           " * render/sheen.h says what the numbers are. */\n\n");
    printf("/* E(mu, r) [r][mu] */\n#define PK_SHEEN_E_INIT \\\n{ \\\n");
    for (int r = 0; r < PK_SH_R; r++) {
        printf("  {");
        for (int m = 0; m < PK_SH_MU; m++)
            printf("%s%.7ff", m ? ", " : "", sheen_gen_e(sheen_gen_r(r), sheen_gen_mu(m), SHEEN_GEN_N));
        printf("}%s \\\n", r == PK_SH_R - 1 ? "" : ",");
    }
    printf("}\n");
    return 0;
}
