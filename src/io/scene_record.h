/*
 * scene_record.h - the "record" forms of the JSON scene (docs/scene-format.md,
 * "Records"): a material, light, environment or medium written field by field
 * as the scene holds it, so that `paprsek convert` (scene_write_json.c) can
 * write any scene the library reads and the JSON reader (scene_json.c) gets
 * back the same bits. One table per kind names the plain fields; the writer
 * and the reader both walk it, so that they cannot disagree. Fields that are
 * not plain numbers (texture maps, media, grids, images) are handled by name
 * beside the tables.
 */
#ifndef PK_SCENE_RECORD_H
#define PK_SCENE_RECORD_H

#include "../scene/scene.h"

#include <stddef.h>

/* REC_WRAP: a texture's clamp mask (TEX_CLAMP_*, a uint8_t), written as
 * false (repeat), true (clamp), "u" or "v" (clamp along that axis only) */
typedef enum rec_type { REC_FLOAT, REC_VEC3, REC_INT, REC_U8, REC_BOOL, REC_F9, REC_F16, REC_F2, REC_WRAP } rec_type;

typedef struct rec_field {
    const char *name;
    rec_type type;
    size_t offset;
} rec_field;

/* The plain fields of a material record (the maps and the media are "map_*",
 * "interior" and "exterior"). */
PK_HIDDEN extern const rec_field rec_material[];
PK_HIDDEN extern const size_t rec_nmaterial;
/* (The maps of a material: material.h's MATERIAL_MAPS, material_map_names
 * and material_map_offsets.) */
/* The plain fields of a texture reference (the image is "image" or "pixels"). */
PK_HIDDEN extern const rec_field rec_texref[];
PK_HIDDEN extern const size_t rec_ntexref;
PK_HIDDEN extern const rec_field rec_light[];
PK_HIDDEN extern const size_t rec_nlight;
/* The environment (the map's pixels are "map"). */
PK_HIDDEN extern const rec_field rec_env[];
PK_HIDDEN extern const size_t rec_nenv;
/* A medium (its grids are "density", "albedo_grid", "emission_grid"). */
PK_HIDDEN extern const rec_field rec_medium[];
PK_HIDDEN extern const size_t rec_nmedium;

/* Pixel files (a texture's level 0, the environment map, a medium's grid)
 * hold the numbers as they are in memory: little-endian floats or bytes, no
 * header (the record gives the sizes). */

#endif
