/*
 * create_material.h - materials from named parameters: one creator per
 * material type, each reading its parameters from a pdict and calling the
 * scene's constructors (scene/material.h). The JSON reader (through the
 * cJSON adapter) and the public scene-building API (pk_params) both come
 * here, so a material reads the same however it is described. The type
 * names and parameter names are the JSON scene format's
 * (docs/scene-format.md, docs/materials.md).
 */
#ifndef PK_CREATE_MATERIAL_H
#define PK_CREATE_MATERIAL_H

#include "../scene/material.h"
#include "pdict.h"

/* Reads the material d describes into *m (material_init'ed here): the type
 * its "type" entry names, or, without one, the OBJ/MTL record ("kd", "ks",
 * "ke", ... as in an MTL file). The type's parameters are declared and the
 * others reported (pd_report_unused) before any value is read; "interior"
 * and "exterior" are declared but left to the caller, which knows the
 * media. Errors: an unknown type, a value out of range, a duplicate key,
 * out of memory, each at its entry (pd_fail). */
PK_HIDDEN pk_status create_material(pdict *d, material *m);

#endif
