/*
 * create_light.h - lights from named parameters: the JSON scene's point,
 * spot and distant lights (docs/scene-format.md, "lights"), read from a
 * pdict by the JSON reader and by pk_scene_add_light alike.
 */
#ifndef PK_CREATE_LIGHT_H
#define PK_CREATE_LIGHT_H

#include "../scene/scene.h"
#include "pdict.h"

/* Adds the light d describes to s: its "type" entry ("point", the default,
 * "spot" or "distant") and the type's parameters (declared, the others
 * reported first). Errors at their entries (pd_fail). */
PK_HIDDEN pk_status create_light(pdict *d, pk_scene *s);

#endif
