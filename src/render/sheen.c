/*
 * sheen.c - the CPU's copy of the sheen's albedo table (sheen.h; the numbers
 * are sheen_table.inc, written by bench/sheen_table.c).
 */
#include "sheen.h"

#include "sheen_table.inc"

const float pk_sheen_e[PK_SH_R][PK_SH_MU] = PK_SHEEN_E_INIT;
