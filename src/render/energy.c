/*
 * energy.c - the CPU's copy of the albedo tables of energy compensation
 * (energy.h; the numbers are energy_tables.inc, written by
 * bench/energy_tables.c).
 */
#include "energy.h"

#include "energy_tables.inc"

const float pk_energy_e[2][PK_EN_ALPHA][PK_EN_MU] = PK_ENERGY_E_INIT;
const float pk_energy_eavg[2][PK_EN_ALPHA] = PK_ENERGY_EAVG_INIT;
const float pk_energy_d[2][2][PK_EN_DETA][PK_EN_DALPHA][PK_EN_DMU] = PK_ENERGY_D_INIT;
