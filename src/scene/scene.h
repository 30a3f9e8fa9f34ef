/*
 * scene.h - the in-memory scene: positions, normals, triangles in file order,
 * analytic spheres, materials, point lights, camera and render settings, and
 * object-space meshes with their instances. Loaders (io/) fill it through
 * the scene_add_* builders and then call scene_commit, which flattens the
 * instances into the triangle list, validates the scene and derives what
 * rendering needs.
 */
#ifndef PK_SCENE_H
#define PK_SCENE_H

#include "../math/tri.h"
#include "../math/vec3.h"
#include "../math/xform.h"
#include "../paprsek_internal.h"
#include "material.h"
#include "medium.h"
#include "texture.h"

/* Triangle k is the k-th triangle the file produced (fan order). */
typedef struct triangle {
    uint32_t v[3];   /* indices into positions */
    int32_t n[3];    /* indices into normals, -1 when the face has none */
    int32_t t[3];    /* indices into uvs, -1 when the face has none */
    uint32_t material;
} triangle;

/* A vertex colour, linear RGB and alpha (glTF's COLOR_0). */
typedef struct rgba {
    float r, g, b, a;
} rgba;

/* A vertex tangent (glTF's TANGENT): the unit direction t of increasing u
 * and the handedness w (+1 or -1): the bitangent, the direction of
 * increasing v, is w (n x t) for the vertex normal n. w = 0: none. */
typedef struct vtangent {
    vec3 t;
    float w;
} vtangent;

/* A texture coordinate (OBJ vt: u to the right, v up). */
typedef struct uv2 {
    float u, v;
} uv2;

typedef struct sphere {
    vec3 center;     /* world space */
    float radius;    /* > 0 */
    uint32_t material;
} sphere;

/* How a spot light fades between its inner and outer cones (t: where the
 * direction's cosine lies, 0 at cos_outer, 1 at cos_inner). */
enum {
    SPOT_FALLOFF_SMOOTHSTEP = 0, /* pbrt-v4: smoothstep(t) */
    SPOT_FALLOFF_ANGLE = 1,      /* Mitsuba: linear in the angle, not the cosine */
    SPOT_FALLOFF_SQUARED = 2     /* glTF KHR_lights_punctual: t^2 */
};

/* A point light, a spot light (spot_dir non-zero) or a distant light
 * (distant). Zero-initialise, then set what applies. */
typedef struct point_light {
    vec3 position;   /* world space; distant: the unit direction toward the light */
    vec3 intensity;  /* radiant intensity, linear RGB (W/sr per channel); distant: the
                        irradiance (W/m^2) of a surface that faces the light */
    vec3 spot_dir;   /* unit axis along which a spot light shines; zero: every direction */
    float cos_inner; /* spot: full intensity within this cone (cosine of its half-angle) */
    float cos_outer; /* spot: nothing outside this one (cos_outer < cos_inner) */
    int spot_falloff;/* SPOT_FALLOFF_* */
    bool distant;
    /* An image that multiplies the intensity by direction (LIGHT_MAP_*;
     * LIGHT_MAP_NONE: none): map_tex is the scene's texture, looked up at
     * its nearest texel (row 0 on top), in the light's frame: a world
     * direction d from the light is to_light d (row-major 3x3, normalised
     * after). A goniometric map is the equal-area octahedral square
     * (equal_area_sphere_to_square) of that direction, its value the mean of
     * the texel's channels (grey); a projection map covers the screen window
     * [-proj_sx, proj_sx] x [-proj_sy, proj_sy] of the perspective
     * projection x/(z t), y/(z t) (t = proj_tan = tan(fov/2)) along +z, its
     * value the texel's colour, nothing outside it (row 0 at -proj_sy). A
     * projector map (Mitsuba's projector) is a projection map divided by
     * cos^3 of the angle from +z, so that it gives a plane facing the light
     * at z = 1 an irradiance of the texel's colour times the intensity.
     * map_mean is the map's mean over the directions it covers (the spot
     * cone bounds a projection's), for the light's share of samples. */
    int map_kind;
    int32_t map_tex;
    float to_light[9];
    float proj_tan, proj_sx, proj_sy;
    float map_mean;
} point_light;

#define LIGHT_MAP_NONE 0
#define LIGHT_MAP_GONIOMETRIC 1
#define LIGHT_MAP_PROJECTION 2
#define LIGHT_MAP_PROJECTOR 3

/* Light from the surroundings (docs/scene-format.md, "environment"): what a
 * ray that leaves the scene sees. Every part is optional and they add up.
 * Directions are world space; a lat-long map is looked up through
 * to_world (row-major 3x3 rotation; identity by default) so that a map's
 * +y is up. set says the scene file described its environment (even as
 * none): without it, a scene with no light at all gets a uniform white one. */
typedef struct scene_environment {
    bool set;
    vec3 radiance;        /* constant radiance, zero = none */
    char *map;            /* lat-long HDR image file (owned; NULL = none), resolved path */
    float *map_rgb;       /* its pixels, linear RGB, row 0 on top (owned; scene_commit loads them) */
    int map_w, map_h;
    float map_scale;      /* multiplies the map (1) */
    float to_world[9];    /* the map's rotation into the world */
    bool has_sun;
    vec3 sun_dir;         /* unit, toward the sun */
    vec3 sun_radiance;    /* radiance of the sun's disc */
    float sun_angle;      /* angular diameter in degrees (0.53) */
    bool has_sky;         /* an analytic daylight sky for the sun's direction */
    float sky_turbidity;  /* 2 .. 10 (3) */
    float sky_scale;      /* multiplies the sky (1) */
    bool sky_hosek;       /* the sky is Hosek-Wilkie's (Mitsuba scenes), not Preetham's */
    vec3 sky_albedo;      /* Hosek-Wilkie: the ground albedo per channel (0.2) */
    bool has_portal;      /* the environment shines only through a rectangle (pbrt-v4's portal) */
    vec3 portal[4];       /* its corners in order, world space: a planar rectangle whose normal
                           * (p3 - p0) x (p1 - p0) points away from the scene, toward the light */
} scene_environment;

/* An object-space mesh: ranges of the scene's mesh_* arrays. Its triangles'
 * indices are relative to the mesh's own first position, normal and uv
 * (-1: none); their materials are scene materials. */
typedef struct scene_mesh {
    size_t first_pos, npos;
    size_t first_nrm, nnrm;
    size_t first_uv, nuv;
    size_t first_tri, ntris;
} scene_mesh;

/* The material of an instance that keeps each triangle's own. */
#define SCENE_MESH_MATERIAL UINT32_MAX

/* A mesh placed in the world. at is the number of world triangles added
 * before it: scene_commit puts its triangles there, so that they keep the
 * file's order among the others. */
typedef struct scene_instance {
    uint32_t mesh;
    uint32_t material;   /* SCENE_MESH_MATERIAL, or a material for all its triangles */
    xform to_world;      /* finite, affine, not singular */
    size_t at;
} scene_instance;

/* An instance that scene_commit kept (not flattened), as renderers and
 * accelerators see it: its triangle k has hit number prim0 + k, after every
 * triangle and sphere of the world arrays (instances in their file order,
 * so numbers ascend with the instance). Built by scene_commit. */
typedef struct scene_kept {
    xform to_world;      /* object to world */
    float nrm[9];        /* normals to world: xform_normal_matrix(to_world), as flattening uses */
    uint32_t mesh;
    uint32_t material;   /* SCENE_MESH_MATERIAL or the material of all its triangles */
    uint32_t prim0;      /* hit number of its triangle 0 */
} scene_kept;

/* scene_commit's rule (config scene.instances=auto): instances stay
 * instances when flattening them would add at least this many triangles;
 * below it every instance is flattened, as it always was. */
#define SCENE_KEEP_MIN_TRIS ((size_t)1 << 22)

/* Render settings a scene file may carry; a field is set when its has_ flag is. */
typedef struct scene_render_settings {
    pk_render_options opt;
    bool has_width, has_height, has_spp, has_light_samples, has_max_depth, has_threads,
        has_accel, has_fresnel, has_seed, has_integrator, has_regularize, has_light_tree, has_clamp_indirect,
        has_energy_compensation, has_filter;
} scene_render_settings;

/* Invariants (scene_check tests them after commit):
 *  1. every triangle's v[] < npositions, n[] is -1 or < nnormals, t[] is -1
 *     or < nuvs, material < nmaterials;
 *  2. every position, normal and uv is finite;
 *  7. every material's image maps name a texture < ntextures, and
 *     texture_bytes is the sum of the textures' bytes;
 *  3. every sphere has a finite center and radius > 0, material < nmaterials;
 *  4. material 0 exists and is the neutral grey default;
 *  5. after commit, degenerate[k] says whether triangle k can never be hit,
 *     and emissive lists the triangles whose material has ke > 0 (non-degenerate);
 *  6. the name index finds, for every material's name, a material of that name
 *     that is not older (the newest, by construction);
 *  8. every mesh's ranges lie in the mesh_* arrays and its triangles' indices
 *     within its own ranges; every instance names a mesh < nmeshes and a
 *     material < nmaterials (or SCENE_MESH_MATERIAL); after commit every
 *     instance is either in the triangle list or kept (nflattened ==
 *     ninstances);
 *  9. kept[i].prim0 = ntris + nspheres + the triangles of kept[0..i-1]'s
 *     meshes, and the last of them fits below PK_NO_HIT; no kept instance
 *     emits light (emitting instances are always flattened: lights are
 *     world triangles). */
struct pk_scene {
    pk_allocator alloc;
    char *name;             /* file name for messages and statistics */

    vec3 *positions; size_t npositions, cap_positions;
    vec3 *normals;   size_t nnormals, cap_normals;
    uv2 *uvs;        size_t nuvs, cap_uvs;
    triangle *tris;  size_t ntris, cap_tris;
    /* Vertex colours by position: NULL when no vertex has one, else one
     * for each position (white where none was given; scene_set_color) */
    rgba *colors;    size_t cap_colors;
    /* Vertex tangents by position: NULL when no vertex has one, else one
     * for each position (w = 0 where none was given; scene_set_tangent) */
    vtangent *tangents; size_t cap_tangents;
    /* A second texture-coordinate set by position (glTF's TEXCOORD_1, which
     * textures with tex_ref.uvset 1 read): NULL when no vertex has one, else
     * one for each position ((0, 0) where none was given; scene_set_uv1) */
    uv2 *uvs1;       size_t cap_uvs1;
    sphere *spheres; size_t nspheres, cap_spheres;
    material *materials; size_t nmaterials, cap_materials;
    /* Name index: open addressing, mat_slots (a power of two, > 2 * nmaterials)
     * slots holding 1 + the newest material of a name, 0 when empty. */
    uint32_t *mat_index; size_t mat_slots;
    point_light *lights; size_t nlights, cap_lights;
    /* Images the materials' maps use, each file loaded once per decode mode
     * (texture_load). */
    texture *textures; size_t ntextures, cap_textures;
    size_t texture_bytes;
    /* The nodes of procedural texture expressions (TEX_EXPR maps name runs
     * of them; scene_add_tex_nodes). */
    tex_node *tex_nodes; size_t ntex_nodes, cap_tex_nodes;

    /* Participating media (medium.h), numbered as materials name them. */
    medium *media; size_t nmedia, cap_media;
    int32_t camera_medium;  /* the medium the camera sits in: MEDIUM_NONE (default) or a medium */
    size_t medium_bytes;    /* the media's grids and majorants (derived by scene_commit) */

    vec3 ambient;           /* ambient light; zero unless the scene asks */
    scene_environment env;  /* the surroundings; nothing unless the scene asks */
    bool has_camera;
    pk_camera camera;
    scene_render_settings render;

    /* the graphics state of a scene built through the API (pk_scene_create;
     * io/scene_build.h), NULL for scenes read from files; freed with the scene */
    struct scene_builder *builder;

    /* derived by scene_commit */
    bool committed;
    uint8_t *degenerate;    /* ntris flags */
    size_t ndegenerate;
    bool has_cutout;        /* a material has map_d */
    bool has_textured;      /* a material has a map other than map_d (its textured flag) */
    bool has_emission_maps; /* an emitting material has map_ke */
    bool has_interfaces;    /* a material is MAT_INTERFACE */
    uint32_t *emissive;     /* indices of emissive triangles */
    size_t nemissive;
    aabb bounds;

    /* Object-space meshes and their instances (scene_capture_mesh,
     * scene_add_instance). scene_commit flattens instances [nflattened,
     * ninstances) into the world arrays above or keeps them (kept: see
     * SCENE_KEEP_MIN_TRIS and the config key scene.instances). */
    vec3 *mesh_positions; size_t nmesh_positions, cap_mesh_positions;
    vec3 *mesh_normals;   size_t nmesh_normals, cap_mesh_normals;
    uv2 *mesh_uvs;        size_t nmesh_uvs, cap_mesh_uvs;
    rgba *mesh_colors;    size_t cap_mesh_colors;  /* NULL, or one for each mesh position */
    vtangent *mesh_tangents; size_t cap_mesh_tangents; /* NULL, or one for each mesh position (object space) */
    uv2 *mesh_uvs1;       size_t cap_mesh_uvs1;    /* NULL, or one for each mesh position */
    triangle *mesh_tris;  size_t nmesh_tris, cap_mesh_tris;
    scene_mesh *meshes;   size_t nmeshes, cap_meshes;
    scene_instance *instances; size_t ninstances, cap_instances;
    size_t nflattened;
    scene_kept *kept;     size_t nkept, cap_kept;
    size_t nkept_tris;    /* triangles the kept instances place (hit numbers past ntris + nspheres) */
    aabb kept_bounds;     /* of the kept instances' triangles, in world space (in bounds too) */
};

/* An empty scene with the default material 0 ("default", grey 0.5 diffuse). */
PK_HIDDEN pk_status scene_create(pk_context *ctx, const char *name, pk_scene **out);
PK_HIDDEN void scene_destroy(pk_scene *s);

/* Builders: return PK_OK or latch an error in ctx (PK_ERR_NOMEM / PK_ERR_LIMIT). */
PK_HIDDEN pk_status scene_add_position(pk_context *ctx, pk_scene *s, vec3 p);
PK_HIDDEN pk_status scene_add_normal(pk_context *ctx, pk_scene *s, vec3 n);
PK_HIDDEN pk_status scene_add_uv(pk_context *ctx, pk_scene *s, uv2 t);
/* Gives position i (< npositions) the vertex colour c: the first colour of
 * a scene gives every other position white. */
PK_HIDDEN pk_status scene_set_color(pk_context *ctx, pk_scene *s, size_t i, rgba c);
/* Gives position i (< npositions) the tangent t (world space, as the
 * position: t.t of unit length, t.w +1 or -1): the first tangent of a
 * scene gives every other position none (w = 0). */
PK_HIDDEN pk_status scene_set_tangent(pk_context *ctx, pk_scene *s, size_t i, vtangent t);
/* Gives position i (< npositions) the second set's texture coordinate t
 * (scene's convention, v up): the first of a scene gives every other
 * position (0, 0). */
PK_HIDDEN pk_status scene_set_uv1(pk_context *ctx, pk_scene *s, size_t i, uv2 t);
PK_HIDDEN pk_status scene_add_triangle(pk_context *ctx, pk_scene *s, const triangle *t);
PK_HIDDEN pk_status scene_add_sphere(pk_context *ctx, pk_scene *s, const sphere *sp);
/* Appends an expression of n procedural nodes (1 <= n <= TEX_MAX_NODES,
 * operands earlier in the run) and sets *r to it (kind TEX_EXPR, the
 * identity uv transform). Refuses a malformed run. */
PK_HIDDEN pk_status scene_add_tex_nodes(pk_context *ctx, pk_scene *s, const tex_node *nodes, int n, tex_ref *r);
/* Whether nodes[0..n-1] is a well-formed expression for a scene with
 * ntextures textures (operands earlier, kinds and images in range). */
PK_HIDDEN bool tex_nodes_valid(const tex_node *nodes, int n, size_t ntextures);

/* Lights: the one way to add them (the readers and the scene API). Each
 * checks what every light of its kind must be (finite, not negative; axes
 * and directions of unit length, as the caller normalised them) and
 * latches PK_ERR_INVALID_ARGUMENT otherwise; readers check first, with
 * messages that say where in the file. */
/* A point light at position (world) of radiant intensity (W/sr per channel). */
PK_HIDDEN pk_status scene_light_point(pk_context *ctx, pk_scene *s, vec3 position, vec3 intensity);
/* A spot light at position shining along the unit axis: full intensity
 * within the cone of cosine cos_inner, nothing outside cos_outer (<=
 * cos_inner), fading between as falloff (SPOT_FALLOFF_*) says. */
PK_HIDDEN pk_status scene_light_spot(pk_context *ctx, pk_scene *s, vec3 position, vec3 axis, float cos_inner,
                                     float cos_outer, int falloff, vec3 intensity);
/* A point light at position whose intensity is multiplied, by direction,
 * by the image map_tex (a texture of the scene) as kind (LIGHT_MAP_
 * GONIOMETRIC or _PROJECTION) says, in the frame to_light (row-major 3x3,
 * world to the map's frame; invertible); a projection covers the window
 * [-sx, sx] x [-sy, sy] at tan_half_fov (point_light). The map's mean and a
 * projection's bounding cone are computed here. power > 0 multiplies the
 * intensity by power over the map's integral over directions (pbrt-v4's
 * "power" of these lights, which leaves the intensity's own size in). */
PK_HIDDEN pk_status scene_light_mapped(pk_context *ctx, pk_scene *s, vec3 position, vec3 intensity, int kind,
                                       int32_t map_tex, const float to_light[9], float tan_half_fov, float sx,
                                       float sy, float power);
/* A distant light from the unit direction to_light, giving irradiance on a
 * surface facing it. */
PK_HIDDEN pk_status scene_light_distant(pk_context *ctx, pk_scene *s, vec3 to_light, vec3 irradiance);
/* The environment: the one way to describe it (readers and the API). Each
 * sets the environment (env.set) and checks what it must be, latching
 * PK_ERR_INVALID_ARGUMENT otherwise; readers check first, with messages
 * that say where in the file. */
/* The scene describes its environment as nothing: no light from it, and
 * no default white one for a scene without lights. */
PK_HIDDEN void scene_env_none(pk_scene *s);
/* Adds a constant radiance to the environment. */
PK_HIDDEN void scene_env_add_radiance(pk_scene *s, vec3 radiance);
/* The environment's frame: the rotation to_world (row-major 3x3) that
 * turns its map, and the grid a sky is baked on, into the world. */
PK_HIDDEN void scene_env_frame(pk_scene *s, const float to_world[9]);
/* The image map: the lat-long file at path (copied), multiplied by scale
 * (>= 0). The file is read now, so that a bad one is reported where it is
 * named; one map per scene (a second is PK_ERR_UNSUPPORTED). */
PK_HIDDEN pk_status scene_env_map(pk_context *ctx, pk_scene *s, const char *path, float scale);
/* The same from pixels already decoded (w x h linear RGB, row 0 on top),
 * which the scene takes (freed on failure); name stands for the file. */
PK_HIDDEN pk_status scene_env_map_pixels(pk_context *ctx, pk_scene *s, const char *name, float *rgb, int w, int h,
                                         float scale);
/* The sun: a disc of angular diameter angle (degrees, in (0, 90]) toward
 * the unit direction to_sun, of uniform radiance (>= 0). */
PK_HIDDEN pk_status scene_env_sun(pk_context *ctx, pk_scene *s, vec3 to_sun, vec3 radiance, float angle);
/* The radiance of a sun disc of angular diameter angle (degrees) that gives
 * irradiance on a surface facing it (E = pi L sin^2 of the half-angle). */
PK_HIDDEN vec3 scene_sun_radiance(vec3 irradiance, float angle);
/* An analytic daylight sky lit by the sun in the unit direction to_sun:
 * Preetham's, or Hosek and Wilkie's (hosek; with the ground's albedo per
 * channel, 0..1) as Mitsuba evaluates it; turbidity in 1..10, scale >= 0. */
PK_HIDDEN pk_status scene_env_sky(pk_context *ctx, pk_scene *s, vec3 to_sun, float turbidity, float scale, bool hosek,
                                  vec3 albedo);
/* Scales everything that emits by k: materials' emission, lights, media's
 * emission and the environment (pbrt-v4's sensor: ISO x exposure time). */
PK_HIDDEN void scene_scale_emission(pk_scene *s, float k);
/* Render settings a scene carries, each marked as the scene's: an integer
 * option of pk_int_options by its name ("width", "spp", "max_depth", ...;
 * out of the option's range, or not an option, PK_ERR_INVALID_ARGUMENT),
 * the accelerator, the integrator, Fresnel on or off, and the clamp of
 * indirect light (0: off; not negative). Readers check first, with messages
 * that say where in the file. */
PK_HIDDEN pk_status scene_render_int(pk_context *ctx, pk_scene *s, const char *name, int v);
PK_HIDDEN void scene_render_accel(pk_scene *s, pk_accel_kind kind);
PK_HIDDEN void scene_render_integrator(pk_scene *s, pk_integrator_kind kind);
PK_HIDDEN void scene_render_fresnel(pk_scene *s, bool on);
/* Energy compensation of rough microfacet lobes on or off (pk_render_options.energy_compensation). */
PK_HIDDEN void scene_render_energy_compensation(pk_scene *s, bool on);
PK_HIDDEN pk_status scene_render_clamp(pk_context *ctx, pk_scene *s, float clamp_indirect);
/* The pixel filter (options_check_filter's refusals, latched). */
PK_HIDDEN pk_status scene_render_filter(pk_context *ctx, pk_scene *s, const pk_filter *f);
/* Adds a material initialised like MTL's defaults (kd 0.8, ks 0, ns 1, ni 1, d 1,
 * illum 2) named name; *index receives its number. A later material of the same
 * name replaces the earlier one for scene_find_material. */
PK_HIDDEN pk_status scene_add_material(pk_context *ctx, pk_scene *s, const char *name, uint32_t *index);
/* Adds a copy of material mat named name (a variant a reader makes for one
 * shape); *index receives its number. */
PK_HIDDEN pk_status scene_material_copy(pk_context *ctx, pk_scene *s, uint32_t mat, const char *name, uint32_t *index);
/* Area emission on a shape: a copy of material mat named name that emits
 * radiance ke, from its front only unless two_sided. */
PK_HIDDEN pk_status scene_material_with_emission(pk_context *ctx, pk_scene *s, uint32_t mat, const char *name, vec3 ke,
                                                 bool two_sided, uint32_t *index);
/* How deep the mixes (MAT_MIX) under material mat nest: 0 for a material
 * that is not a mix, 1 for a mix of two others, ...; more than
 * MATERIAL_MIX_DEPTH where a mix names a material that does not come
 * before it. (scene_material_with_emission and scene_material_with_media
 * copy a mix with copies of its materials, so that whichever a hit meets
 * emits, or bounds the media.) */
PK_HIDDEN int scene_mix_depth(const pk_scene *s, uint32_t mat);
/* Number of the newest material named name; -1 when absent. Constant time
 * (a hash index), so that files with many materials and usemtl statements
 * do not take quadratic time. */
PK_HIDDEN int64_t scene_find_material(const pk_scene *s, const char *name);
/* Adds medium *m (medium.h; its name, if any, is looked up by
 * scene_find_medium) and takes what it owns (name, grids): on failure they
 * are freed. *index receives its number. Its values are checked by
 * scene_commit (messages name the medium). */
PK_HIDDEN pk_status scene_add_medium(pk_context *ctx, pk_scene *s, medium *m, uint32_t *index);
/* The material that is material mat with the media med_in (interior) and
 * med_out (exterior) on its sides: mat itself when it has them already,
 * else a copy made once per (mat, med_in, med_out) and named
 * "NAME@in,out" (so that finding mat's own name still finds mat). For
 * readers whose shapes name their media apart from their materials. */
PK_HIDDEN pk_status scene_material_with_media(pk_context *ctx, pk_scene *s, uint32_t mat, int32_t med_in,
                                              int32_t med_out, uint32_t *out);
/* The medium the camera sits in: MEDIUM_NONE or a medium's number (checked
 * by scene_commit with the media materials name). */
static inline void scene_set_camera_medium(pk_scene *s, int32_t med) { s->camera_medium = med; }
/* Number of the newest medium named name; -1 when absent. */
PK_HIDDEN int64_t scene_find_medium(const pk_scene *s, const char *name);
/* A medium's coefficients from absorption sigma_a and scattering sigma_s
 * (per unit length, not negative) times scale: sigma_t = (sigma_a +
 * sigma_s) scale and albedo sigma_s / (sigma_a + sigma_s), at most 1 (1
 * where nothing interacts, which no path can see). */
PK_HIDDEN void medium_set_coefficients(medium *m, vec3 sigma_a, vec3 sigma_s, float scale);
/* Frees what a medium owns (its name, grids and majorants). */
PK_HIDDEN void medium_free(const pk_allocator *a, medium *m);
/* Checks every medium (values, grids, placement, the voxel limit) and the
 * media that materials and the camera name, and derives each medium's
 * world_to_grid, bounds, majorant grid and sigma_max, and medium_bytes
 * (scene_commit calls it). */
PK_HIDDEN pk_status scene_media_prepare(pk_context *ctx, pk_scene *s);
/* Whether the scene has participating media to render: a medium some
 * material or the camera refers to. */
PK_HIDDEN bool scene_has_media(const pk_scene *s);
/* The empty environment (nothing set, identity rotation, scales 1, sun 0.53 degrees). */
PK_HIDDEN void scene_env_init(scene_environment *env);
/* The rotation by deg degrees about +y (counter-clockwise seen from above),
 * row-major 3x3: an environment map's to_world. */
PK_HIDDEN void scene_rotation_y(float deg, float m[9]);
/* Frees what env owns and empties it. */
PK_HIDDEN void scene_env_clear(const pk_allocator *a, scene_environment *env);
/* Loads env->map into map_rgb unless loaded (a no-op without a map). */
PK_HIDDEN pk_status scene_env_load(pk_context *ctx, scene_environment *env);

/* Meshes and instances (step one: scene_commit flattens them; renderers see
 * triangles). scene_capture_mesh turns the world geometry added since
 * (pos0, nrm0, uv0, tri0) - the counts of positions, normals, uvs and
 * triangles when the reader began the object - into a new mesh *mesh, in
 * the space it was written in, and removes it from the world arrays. Its
 * triangles must use only the vertices added since; no instance may have
 * been added in between. */
PK_HIDDEN pk_status scene_capture_mesh(pk_context *ctx, pk_scene *s, size_t pos0, size_t nrm0, size_t uv0,
                                       size_t tri0, uint32_t *mesh);
/* Places mesh by to_world (finite, affine, not singular: else
 * PK_ERR_INVALID_ARGUMENT), with material mat for all its triangles or
 * SCENE_MESH_MATERIAL for their own. Its triangles take their place after
 * the triangles added so far. */
PK_HIDDEN pk_status scene_add_instance(pk_context *ctx, pk_scene *s, uint32_t mesh, const xform *to_world,
                                       uint32_t mat);

/* Flattens the instances not yet flattened (positions by to_world, normals
 * by its inverse transpose, renormalised) or keeps them as instances
 * (ctx's config scene.instances: auto keeps instances that do not emit,
 * of meshes placed at least twice, when they would flatten to
 * SCENE_KEEP_MIN_TRIS triangles or more; flatten; keep), then validates
 * and derives (degenerate flags, emissive list, bounds).
 * PK_ERR_EMPTY_SCENE when nothing can be hit. Warns about degenerate triangles. */
PK_HIDDEN pk_status scene_commit(pk_context *ctx, pk_scene *s);
/* Tests the invariants above; returns false and fills why (if non-NULL). */
PK_HIDDEN bool scene_check(const pk_scene *s, char *why, size_t why_size);

/* Geometry of triangle k. */
static inline PK_HD void scene_tri_verts(const pk_scene *s, size_t k, vec3 *a, vec3 *b, vec3 *c)
{
    const triangle *t = &s->tris[k];
    *a = s->positions[t->v[0]];
    *b = s->positions[t->v[1]];
    *c = s->positions[t->v[2]];
}

/* ---- the built-in scene (the file readers are in io/readers.h) ---- */

/* Fills s with the built-in Cornell box. Does not commit. */
PK_HIDDEN pk_status scene_build_cornell(pk_context *ctx, pk_scene *s);

#endif
