/*
 * paprsek.h - the whole public interface of Paprsek, a ray tracer.
 *
 * Everything a program may use is declared here; everything else is private.
 * Conventions: functions return pk_status (PK_OK == 0); fallible constructors
 * fill an out-parameter; the first error of a context is latched with a message
 * of the form "file:line: what is wrong" (pk_context_error). The library never
 * prints, exits or aborts because of its input. Every object has one owner;
 * pk_x_destroy(NULL) is a no-op. The header compiles as C11 and as C++.
 */
#ifndef PAPRSEK_H
#define PAPRSEK_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(PK_BUILDING_LIBRARY) && defined(__GNUC__)
#define PK_API __attribute__((visibility("default")))
#else
#define PK_API
#endif

#define PK_VERSION_MAJOR 0
#define PK_VERSION_MINOR 1
#define PK_VERSION_PATCH 0
#define PK_VERSION_STRING "0.1.0"

typedef enum pk_status {
    PK_OK = 0,
    PK_ERR_INVALID_ARGUMENT = 1, /* a bad value passed through the API */
    PK_ERR_IO = 2,               /* a file could not be read or written */
    PK_ERR_PARSE = 3,            /* a file is malformed */
    PK_ERR_LIMIT = 4,            /* a size, count or depth is beyond the limits */
    PK_ERR_NOMEM = 5,            /* an allocation failed */
    PK_ERR_UNSUPPORTED = 6,      /* the feature is not built in (e.g. Embree) */
    PK_ERR_CANCELLED = 7,        /* the render was stopped through its cancel flag */
    PK_ERR_EMPTY_SCENE = 8       /* nothing renderable */
} pk_status;

/* ---- context: allocator, error latch, warnings ------------------------- */

typedef struct pk_context pk_context;

/* One allocation hook, as in Lua: realloc(user, ptr, size); size 0 frees and
 * returns NULL. It may return NULL for size > 0 to report failure. */
typedef struct pk_allocator {
    void *(*realloc)(void *user, void *ptr, size_t size);
    void *user;
} pk_allocator;

typedef void (*pk_warning_fn)(void *user, const char *message);

/* alloc may be NULL (the C library's malloc). The context copies *alloc. */
PK_API pk_status pk_context_create(const pk_allocator *alloc, pk_context **out);
PK_API void pk_context_destroy(pk_context *ctx);
/* The first error since the last clear ("" when there was none). Owned by ctx. */
PK_API const char *pk_context_error(const pk_context *ctx);
PK_API pk_status pk_context_status(const pk_context *ctx);
PK_API void pk_context_clear_error(pk_context *ctx);
/* Warnings (unknown OBJ statements, missing MTL, dropped faces...) go to fn;
 * without a handler they are dropped. */
PK_API void pk_context_set_warning_handler(pk_context *ctx, pk_warning_fn fn, void *user);

/* Where the library's files come from. By default every file the library
 * reads (a scene, the MTL files an OBJ names, the OBJ meshes of a JSON scene,
 * any file a scene refers to) is read from the file system. A file reader
 * replaces that for every read through ctx: a program can serve files from
 * memory, from an archive or from another machine, or record which files a
 * scene needs (paprsek-mpi does both, docs/distributed.md).
 *
 * The reader is called with the path as the library would open it (the
 * scene's folder joined with the name the scene gives). On success it
 * returns PK_OK and sets *data and *size to the whole file's bytes; they stay
 * the reader's and must stay valid until the reader returns to the library
 * again or is replaced (the library copies them at once). Files larger than
 * PK_MAX_FILE_BYTES are refused as from the file system. On failure it
 * returns a status (PK_ERR_IO for a file it does not have) and may write a
 * short reason, NUL-terminated, into why (why_cap bytes, at least 128): the
 * library's message is then "path: reason". The library also asks the reader
 * whether a file exists where it tries more than one name (an OBJ's mtllib
 * line whose whole rest may name one file): a reader answers that as a read.
 * fn NULL restores reading from the file system. */
typedef pk_status (*pk_file_reader_fn)(void *user, const char *path, const void **data, size_t *size,
                                       char *why, size_t why_cap);
PK_API void pk_context_set_file_reader(pk_context *ctx, pk_file_reader_fn fn, void *user);

/* The back ends' settings, as comma-separated key=value pairs (the shape of
 * Embree's rtcNewDevice config), e.g. "bvh.quality=fast,cpu.isa=avx2". They
 * are read when an accelerator (or a renderer, which builds one) is created
 * through ctx, so a change applies to the ones created afterwards. The
 * library reads no environment variable: this is the only way in.
 *   cpu.isa         auto (default: AVX-512 where the CPU has it, else AVX2)
 *                   or avx2 (the AVX2 kernels of PK_ACCEL_BVH everywhere);
 *                   both find the same hits
 *   bvh.quality     high (default: with spatial splits) or fast (without:
 *                   a faster build, slower traversal); the same hits
 *   embree.quality  low, medium (default) or high: Embree's build quality
 *   embree.library  the Embree 3 library to load (a path or a soname;
 *                   default libembree3.so.3)
 *   cuda.library    the CUDA driver to load (default libcuda.so.1)
 *   dnnl.library    oneDNN, which runs the denoiser (default libdnnl.so.2)
 *   cuda.traversal  sorted (default) or ordered: the GPU's traversal
 *                   (docs/gpu.md); the same closest hits
 *   cuda.leaf       16 (default), 8 or 4: the most triangles in a leaf of
 *                   the GPU's tree; the same closest hits
 *   openvdb.module  the library's OpenVDB module, which reads .vdb files (a
 *                   path; default: paprsek_openvdb.so where the library is
 *                   installed, LIBDIR/paprsek, or beside it in the build tree)
 *   cuda.module     the library's CUDA kernels' module (a path; default:
 *                   paprsek_cuda.so, found as paprsek_openvdb.so is)
 *   draco.module    the library's Draco module, which decodes glTF's
 *                   KHR_draco_mesh_compression (a path; default:
 *                   paprsek_draco.so, found as paprsek_openvdb.so is)
 * A library is loaded once per process: the first name that loads stays.
 * Keys not named keep their values (a new context has the defaults); an
 * empty value ("cpu.isa=") restores a key's default; blanks around keys and
 * values are ignored, empty items too; values cannot contain commas. An
 * unknown key or a bad value is PK_ERR_INVALID_ARGUMENT, latched with a
 * message naming the key, and then nothing is changed. */
PK_API pk_status pk_context_set_config(pk_context *ctx, const char *config);
/* The effective configuration, every key with its value in the order above
 * (e.g. "cpu.isa=auto,bvh.quality=high,..."): at most size bytes, NUL
 * included, are written to buf (may be NULL when size is 0); returns the
 * length of the whole text, as snprintf. */
PK_API size_t pk_context_get_config(const pk_context *ctx, char *buf, size_t size);

PK_API const char *pk_status_string(pk_status status);

/* ---- limits (checked on every input) ------------------------------------ */

#define PK_MAX_IMAGE_SIDE 16384
#define PK_MAX_IMAGE_PIXELS (64u * 1024u * 1024u)
#define PK_MAX_SPP 65536
#define PK_MAX_LIGHT_SAMPLES 4096
#define PK_MAX_DEPTH 1024
#define PK_DEFAULT_DEPTH_PATH 64    /* enough for a closed box to converge */
#define PK_DEFAULT_DEPTH_VOLPATH 1024 /* random walks in dense media take hundreds of scatterings; roulette ends them */
#define PK_DEFAULT_DEPTH_WHITTED 8
#define PK_MAX_THREADS 1024
#define PK_MAX_POLYGON_VERTICES 4096
/* Instances (pbrt ObjectInstance, Mitsuba instance, glTF nodes, JSON mesh
 * instances) in one scene: each takes about 200 bytes once placed, so the
 * bound keeps an instance bomb (a short file whose nested objects multiply)
 * below about 3 GiB; past it the scene is refused. */
#define PK_MAX_INSTANCES ((size_t)1 << 24)
#define PK_MAX_FILE_BYTES ((size_t)1 << 31) /* 2 GiB */
/* A JSON scene holds settings, materials, spheres and lights, not meshes; its
 * parsed tree takes tens of bytes per byte of text, hence a smaller bound. */
#define PK_MAX_JSON_BYTES ((size_t)64 << 20) /* 64 MiB */
/* Image textures and environment maps: each side at most PK_MAX_TEXTURE_SIDE
 * pixels and at most PK_MAX_TEXTURE_PIXELS pixels per image (checked before
 * a file is decoded, so that a small compressed file cannot ask for
 * gigabytes); all the textures of a scene together, their mipmaps included,
 * at most PK_MAX_TEXTURE_BYTES. A texture past a bound is left out with a
 * warning, and its material keeps its constant values. */
#define PK_MAX_TEXTURE_SIDE 32768
#define PK_MAX_TEXTURE_PIXELS (64u * 1024u * 1024u)
#define PK_MAX_TEXTURE_BYTES ((size_t)4 << 30) /* 4 GiB */
/* A Mitsuba XML scene file (each included file too); meshes live in their own files. */
#define PK_MAX_XML_BYTES ((size_t)64 << 20) /* 64 MiB */

/* ---- camera, options, statistics ----------------------------------------- */

/* How the camera projects the scene onto the film (pk_camera.projection). */
typedef enum pk_projection {
    PK_PROJECTION_PERSPECTIVE = 0, /* rays from the eye (a pinhole or a thin lens) through the film */
    PK_PROJECTION_ORTHOGRAPHIC = 1 /* parallel rays along the view direction, from the plane of the eye */
} pk_projection;

/* A camera in world space, looking from look_from toward look_at with up
 * upward in the image. fov_deg is the vertical field of view of the
 * perspective projection.
 * lens_radius: 0 is a pinhole (everything sharp); above 0 a thin lens of
 * that radius (scene units) centred on look_from, sharp only at
 * focus_distance, the distance along the view direction to the plane in
 * focus (0: the distance from look_from to look_at). Both projections
 * take a lens.
 * ortho_width: the full width of the orthographic view in scene units (its
 * height follows the image's aspect); 0 is the width the perspective view
 * of fov_deg has at look_at's distance. */
typedef struct pk_camera {
    float look_from[3];
    float look_at[3];
    float up[3];
    float fov_deg;
    float lens_radius;
    float focus_distance;
    int projection;      /* pk_projection */
    float ortho_width;
} pk_camera;

/* Sets every field to its default: at the origin, looking along -z
 * (look_at 0,0,-1), up +y, fov_deg 45, a pinhole (lens_radius 0,
 * focus_distance 0), the perspective projection, ortho_width 0. Start from
 * it, then set what you need, so that fields added in later versions get
 * their defaults. */
PK_API void pk_camera_init(pk_camera *cam);
/* Whether cam is a camera the library accepts (the rule of
 * pk_scene_set_camera and pk_renderer_set_camera): PK_OK, or
 * PK_ERR_INVALID_ARGUMENT with "camera: what is wrong" latched in ctx (ctx
 * may be NULL: nothing is latched). */
PK_API pk_status pk_camera_check(pk_context *ctx, const pk_camera *cam);

typedef enum pk_accel_kind {
    PK_ACCEL_DEFAULT = 0,  /* the best built in (PK_ACCEL_BVH) */
    PK_ACCEL_NONE = 1,     /* every ray tests every primitive */
    PK_ACCEL_MIDPOINT = 2, /* simple BVH (midpoint split), for comparison */
    PK_ACCEL_BVH = 3,      /* binned SAH, wide SIMD BVH */
    PK_ACCEL_EMBREE = 4,   /* Embree 3, when built with it */
    PK_ACCEL_CUDA = 5      /* an NVIDIA GPU (batches of rays only), when built with CUDA */
} pk_accel_kind;

PK_API const char *pk_accel_kind_name(pk_accel_kind kind);
/* Returns PK_OK and sets *out for "none", "midpoint", "bvh", "embree", "cuda". */
PK_API pk_status pk_accel_kind_parse(const char *name, pk_accel_kind *out);
/* 1 when the accelerator is compiled in (for Embree: and its library loads;
 * for CUDA: compiled in, whether or not this machine has a GPU). */
PK_API int pk_accel_available(pk_accel_kind kind);

/* Where a render runs. */
typedef enum pk_device_kind {
    PK_DEVICE_CPU = 0,  /* the CPU's threads, with the accelerator of pk_render_options.accel */
    PK_DEVICE_CUDA = 1  /* an NVIDIA GPU, when built with CUDA: the path tracer, triangles only, on
                           the GPU's own structure (PK_ACCEL_CUDA, which the renderer builds) */
} pk_device_kind;

PK_API const char *pk_device_name(pk_device_kind kind);
/* Returns PK_OK and sets *out for "cpu", "cuda". */
PK_API pk_status pk_device_parse(const char *name, pk_device_kind *out);

typedef enum pk_integrator_kind {
    PK_INTEGRATOR_DEFAULT = 0, /* the path tracer */
    PK_INTEGRATOR_WHITTED = 1, /* direct light, mirror reflection and refraction */
    PK_INTEGRATOR_PATH = 2,    /* path tracing: global illumination, multiple importance sampling */
    PK_INTEGRATOR_VOLPATH = 3  /* path tracing through participating media (the default for scenes with media) */
} pk_integrator_kind;

PK_API const char *pk_integrator_name(pk_integrator_kind kind);
/* Returns PK_OK and sets *out for "whitted", "path", "default". */
PK_API pk_status pk_integrator_parse(const char *name, pk_integrator_kind *out);

/* The pixel filter: how a pixel weighs what its samples see at each offset
 * from its centre. Each sample's position is drawn from the filter's shape
 * (importance sampling) and counts for the pixel it was drawn for only, so
 * images do not depend on threads or tiles. The default, a box of radius
 * 0.5, spreads the samples evenly over the pixel. */
typedef enum pk_filter_type {
    PK_FILTER_BOX = 0,             /* 1 inside the radius */
    PK_FILTER_TRIANGLE = 1,        /* a tent: radius - |x| */
    PK_FILTER_GAUSSIAN = 2,        /* exp(-x^2 / (2 sigma^2)), less its value at the radius */
    PK_FILTER_MITCHELL = 3,        /* Mitchell-Netravali's cubic (b, c) stretched over the radius */
    PK_FILTER_BLACKMAN_HARRIS = 4, /* the 4-term Blackman-Harris window over the radius */
    PK_FILTER_LANCZOS = 5          /* sinc(x) sinc(x / tau) (pbrt-v4's "sinc", Mitsuba's "lanczos") */
} pk_filter_type;

typedef struct pk_filter {
    pk_filter_type type;
    /* half the width of the filter in pixels along x and y (0 < radius <= 16);
     * the filter is the product of its 1-D profile along each axis */
    float radius_x, radius_y;
    float sigma; /* gaussian: the standard deviation in pixels (> 0) */
    float b, c;  /* mitchell: B and C (finite) */
    float tau;   /* lanczos: the number of lobes of the window (> 0) */
} pk_filter;

/* The filter of type with pbrt-v4's defaults: box radius 0.5, triangle 2,
 * gaussian 1.5 (sigma 0.5), mitchell 2 (B = C = 1/3), lanczos 4 (tau 3);
 * blackman-harris (not in pbrt-v4) 1.5. */
PK_API void pk_filter_init(pk_filter *f, pk_filter_type type);
/* "box", "triangle", "gaussian", "mitchell", "blackman-harris", "lanczos". */
PK_API const char *pk_filter_name(pk_filter_type type);
PK_API pk_status pk_filter_parse(const char *name, pk_filter_type *out);

/* Progress of a render: done of total work units (tiles) finished, elapsed
 * seconds since the render call began. Called from one thread, at most a few
 * times per second, and once more at the end (done == total unless the render
 * was cancelled). Returning non-zero cancels the render (PK_ERR_CANCELLED). */
typedef int (*pk_progress_fn)(void *user, uint64_t done, uint64_t total, double elapsed_s);

typedef struct pk_render_options {
    int width, height;   /* pixels */
    int spp;             /* samples per pixel, stratified jitter when > 1 */
    int light_samples;   /* shadow samples per shading point for area lights */
    int max_depth;       /* bounces (path) or reflection/refraction depth (whitted);
                            -1 = the integrator's default (pk_render_options_max_depth) */
    int threads;         /* 0 = all cores */
    pk_accel_kind accel;
    int fresnel;         /* 1 = exact dielectric Fresnel; 0 = fixed Ks/Tf weights */
    int collect_stats;   /* 1 = count rays, tests and nodes (small cost) */
    /* When non-NULL, the render stops soon after *cancel becomes non-zero and
     * returns PK_ERR_CANCELLED; the image then holds the finished tiles. */
    volatile const int *cancel;
    pk_progress_fn progress; /* NULL: no progress reports */
    void *progress_user;
    pk_integrator_kind integrator;
    int seed;            /* the path tracer's noise pattern (0..2^31-1) */
    /* Where to render. PK_DEVICE_CUDA traces on the GPU's own structure,
     * whatever accel says (it reads PK_ACCEL_CUDA afterwards); accel
     * PK_ACCEL_CUDA with PK_DEVICE_CPU means PK_DEVICE_CUDA too (as programs
     * written before this field said it). */
    pk_device_kind device;
    /* Path regularisation (the path tracer): 1 roughens near-specular
     * surfaces (GGX roughness below 0.3 doubled, to 0.1..0.3) once a path
     * has bounced off a rough or diffuse one, which turns caustic fireflies
     * into a smooth, slightly wrong glow: biased, off (0) by default. */
    int regularize;
    /* How the path tracer picks the light it samples at each bounce: 1 by
     * the light's importance to the shading point (its power, distance and
     * orientation, through a tree over the lights: for scenes with many
     * lights), 0 by power alone, -1 (the default) the tree when the scene
     * has 8 or more lights other than the environment, the sun and distant
     * lights. The image converges to the same answer either way. */
    int light_tree;
    /* Indirect clamping (the path tracer): when > 0, the light a sample
     * brings through at least one bounce after the first surface it sees
     * is scaled down so that no component exceeds this value. Removes the
     * rest of the fireflies at the price of a darker, biased image; 0 (the
     * default) is off. */
    float clamp_indirect;
    /* Energy compensation of rough microfacet surfaces (the path tracers):
     * 1 gives back the light that a rough conductor, glass, plastic coat or
     * glTF material loses to scattering between its microfacets (brighter,
     * more saturated rough metals; docs/materials.md), 0 (the default) is
     * off. glTF scenes ask for 1 (pk_scene_get_render_options). */
    int energy_compensation;
    /* The pixel filter (pk_filter; a box of radius 0.5 by default). Filters
     * with negative lobes (mitchell, lanczos) give samples negative weights
     * there, which makes them noisier than the others at equal samples. */
    pk_filter filter;
    /* Transparent background: 1 makes what camera rays see of the
     * surroundings black (their samples add nothing), so the image is
     * colour premultiplied by the coverage (PK_AOV_ALPHA); the environment
     * still lights the scene and is still seen in reflections and through
     * glass. 0 (the default) shows it. CPU only: PK_ERR_UNSUPPORTED on the
     * GPU. */
    int transparent;
} pk_render_options;

/* Arbitrary output variables: what the camera ray of each sample found,
 * averaged over the pixel like the image. A film holds those it was created
 * with (pk_film_create_aovs); renders fill them. */
enum {
    PK_AOV_ALBEDO = 1u,  /* the material's diffuse reflectance; the path tracer takes it at the first
                          * surface that is not a perfect mirror or glass, times their tint (what a
                          * denoiser wants); emitters and the sky their colour over its largest part */
    PK_AOV_NORMAL = 2u,  /* the shading normal, world space, facing the ray, at that same surface */
    PK_AOV_DEPTH = 4u,   /* distance from the camera to the hit (0 where nothing is hit) */
    PK_AOV_HEATMAP = 8u, /* acceleration-structure nodes visited + primitives tested by the camera ray */
    PK_AOV_ALPHA = 16u,  /* coverage: the fraction of the pixel's samples whose camera ray hit a surface
                          * (through map_d holes; glass and mirrors count as surfaces), in all three
                          * channels (pk_write_options.alpha reads the first) */
    PK_AOV_SAMPLES = 32u /* the number of samples of the pixel, in all three channels (adaptive
                          * sampling gives pixels different numbers); the film's counts, no storage */
};
/* "albedo", "normal", "depth", "heatmap", "alpha", "samples" -> PK_AOV_*, 0 when unknown. */
PK_API unsigned pk_aov_parse(const char *name);
PK_API const char *pk_aov_name(unsigned aov);

/* Defaults: 512x512, 1 spp, 32 light samples, depth 8, all threads, default
 * accelerator, Fresnel on, no statistics, no progress callback, a box
 * filter of radius 0.5. */
PK_API void pk_render_options_init(pk_render_options *opt);

/* The integer render options and their ranges: one table serves the API
 * (pk_render_options_check), JSON scenes (the "render" object) and the
 * paprsek program (--name, with '_' written '-'). */
typedef struct pk_int_option {
    const char *name;    /* "width", "light_samples", ... */
    const char *label;   /* as messages say it: "samples per pixel" */
    const char *help;    /* one line for a user */
    int min, max;        /* the accepted range, inclusive */
    int default_value;
    size_t offset;       /* offset of the int field in pk_render_options */
} pk_int_option;

/* The table (static storage); *count receives its length. */
PK_API const pk_int_option *pk_int_options(size_t *count);
/* The entry named name ("light_samples" or "light-samples"), or NULL. */
PK_API const pk_int_option *pk_int_option_find(const char *name);
/* Checks opt against the table, the pixel budget (PK_MAX_IMAGE_PIXELS) and
 * the accelerators built in; latches "what is wrong" in ctx. */
/* The depth a render with these options uses: max_depth, or when it is -1 the
 * integrator's default, PK_DEFAULT_DEPTH_PATH or PK_DEFAULT_DEPTH_WHITTED. */
PK_API int pk_render_options_max_depth(const pk_render_options *opt);
PK_API pk_status pk_render_options_check(pk_context *ctx, const pk_render_options *opt);

typedef struct pk_stats {
    uint64_t rays_camera, rays_shadow, rays_reflection, rays_refraction;
    uint64_t rays_bounce;        /* the path tracer's continuation rays */
    uint64_t intersection_tests; /* ray-primitive tests */
    uint64_t nodes_visited;      /* acceleration-structure nodes */
    double build_us;             /* acceleration build, microseconds */
    double render_s;             /* rendering, seconds (wall clock) */
    int threads;                 /* threads used */
    int accel_builds;            /* acceleration structures built (1 per renderer) */
    uint64_t pixels;             /* pixels rendered (times the renders of a renderer) */
} pk_stats;

/* ---- scenes ------------------------------------------------------------ */

typedef struct pk_scene pk_scene;

/* Loads by extension: .obj (with its MTL files), .json or .xml (Mitsuba). */
PK_API pk_status pk_scene_load_file(pk_context *ctx, const char *path, pk_scene **out);
/* OBJ from memory. name is used in messages; base_dir is where mtllib files are
 * looked up (NULL: MTL files are not read). */
PK_API pk_status pk_scene_load_obj_memory(pk_context *ctx, const char *data, size_t size,
                                          const char *name, const char *base_dir,
                                          pk_scene **out);
/* JSON scene from memory; mesh paths are relative to base_dir. */
PK_API pk_status pk_scene_load_json_memory(pk_context *ctx, const char *data, size_t size,
                                           const char *name, const char *base_dir,
                                           pk_scene **out);
/* As pk_scene_load_file; params (nparams strings "NAME=VALUE") set the
 * parameters ($NAME) of a Mitsuba XML scene over its <default> values; a
 * glTF asset takes camera=N (render /cameras/N instead of the first camera
 * in node order) and variant=NAME (KHR_materials_variants: the materials
 * that the variant NAME maps its primitives to; a name the asset does not
 * have is an error listing its variants); others are warned about. Other formats have no
 * parameters and ignore them. */
PK_API pk_status pk_scene_load_file_params(pk_context *ctx, const char *path, const char *const *params,
                                           size_t nparams, pk_scene **out);
/* A scene of any format from memory: format is "obj", "json", "xml",
 * "pbrt", "gltf" or "glb" (what pk_scene_format returns, or a file's
 * extension without the dot); name is used in messages (NULL: "memory.FORMAT");
 * the files it names are relative to base_dir (NULL: the current folder;
 * for OBJ, NULL reads no material libraries). An unknown format is
 * PK_ERR_INVALID_ARGUMENT. */
PK_API pk_status pk_scene_load_memory(pk_context *ctx, const char *format, const char *data, size_t size,
                                      const char *name, const char *base_dir, pk_scene **out);
/* The format pk_scene_load_file reads path as, chosen by its extension
 * (ASCII case ignored): "obj", "json", "xml", "pbrt" or "gltf" (.gltf and
 * .glb); NULL when no format has that extension. */
PK_API const char *pk_scene_format(const char *path);
/* Mitsuba XML scene from memory; files it names (meshes, includes) are
 * relative to base_dir (NULL: the current folder). */
PK_API pk_status pk_scene_load_xml_memory(pk_context *ctx, const char *data, size_t size,
                                          const char *name, const char *base_dir,
                                          pk_scene **out);
/* The built-in Cornell box (camera, light quad, two boxes). */
PK_API pk_status pk_scene_create_cornell_box(pk_context *ctx, pk_scene **out);
PK_API void pk_scene_destroy(pk_scene *scene);
/* Writes a loaded scene as a Paprsek JSON scene at path (docs/scene-format.md,
 * "Records"), its triangles as binary PLY files and its images, grids and
 * environment map as raw files beside it, named after path: loading that file
 * gives a scene that renders the same bytes. Written under temporary names
 * and renamed into place at the end: on failure nothing is left. A scene the
 * format cannot express (a changed default material, a value that is not
 * finite) is an error that names it. */
PK_API pk_status pk_scene_write_json(pk_context *ctx, const pk_scene *scene, const char *path);

/* Light from the surroundings, replacing the scene's own (docs/scene-format.md,
 * "environment"): a constant radiance plus a lat-long image (PNG, JPEG,
 * OpenEXR, Radiance .hdr or PFM; +y up, looked up as Mitsuba's envmap) times
 * map_scale, turned by rotation degrees about +y. */
typedef struct pk_environment {
    float radiance[3];   /* linear RGB, >= 0 */
    const char *map;     /* image file or NULL */
    float map_scale;     /* >= 0 */
    float rotation;      /* degrees */
} pk_environment;

/* No radiance, no map, scale 1, no rotation. */
PK_API void pk_environment_init(pk_environment *env);
/* Sets the scene's environment (the map is read now); NULL = none (black),
 * which also turns off the white environment that lights a scene with no
 * light of its own. A failure leaves the scene as it was. */
PK_API pk_status pk_scene_set_environment(pk_context *ctx, pk_scene *scene, const pk_environment *env);

typedef struct pk_scene_info {
    size_t triangles;            /* as numbered by the file, degenerate ones included */
    size_t degenerate_triangles; /* never hit */
    size_t spheres, materials, point_lights, emissive_triangles;
    float bounds_min[3], bounds_max[3];
    int has_camera;              /* 0: the camera is framed on the bounds */
    size_t textures;             /* images loaded for texture maps (one per file and decode mode) */
    size_t texture_bytes;        /* their texels, mipmaps included */
    size_t media;                /* participating media (docs/media.md) */
    size_t medium_bytes;         /* their voxel grids and majorant grids */
    int has_media;               /* 1: the camera or a surface bounds a medium (the default integrator is volpath) */
} pk_scene_info;

PK_API void pk_scene_get_info(const pk_scene *scene, pk_scene_info *info);
/* Vertices of triangle k (file numbering) as v0,v1,v2 xyz; PK_ERR_INVALID_ARGUMENT
 * when k is out of range. */
PK_API pk_status pk_scene_get_triangle(const pk_scene *scene, size_t k, float verts[9]);
/* The number of the k-th emissive triangle (k < pk_scene_info.emissive_triangles):
 * the area lights, in triangle order. */
PK_API pk_status pk_scene_get_emissive_triangle(const pk_scene *scene, size_t k, size_t *triangle);
/* The scene's camera, or one framed automatically on its bounds. */
PK_API void pk_scene_get_camera(const pk_scene *scene, pk_camera *cam);
/* Validates (finite, fov in (0,180), look_from != look_at, up not parallel,
 * lens_radius, focus_distance and ortho_width >= 0, a known projection). */
PK_API pk_status pk_scene_set_camera(pk_context *ctx, pk_scene *scene, const pk_camera *cam);
/* The scene's own render settings (JSON "render") over the defaults. */
PK_API void pk_scene_get_render_options(const pk_scene *scene, pk_render_options *opt);
/* Non-zero when the scene file names its samples per pixel (a JSON
 * "render.spp", a Mitsuba sampler's sample_count). */
PK_API int pk_scene_has_sample_count(const pk_scene *scene);
/* Non-zero when the scene file gives the image's width and height (a JSON
 * "render"/"film" size, a Mitsuba film, a pbrt Film, a glTF camera's aspect
 * ratio). */
PK_API int pk_scene_has_image_size(const pk_scene *scene);

/* ---- building scenes ----------------------------------------------------- */

/* A scene built in code rather than read from a file (docs/scene-api.md):
 * pk_scene_create, then materials, meshes, spheres, lights, objects and
 * instances, the camera and environment (pk_scene_set_camera,
 * pk_scene_set_environment), then pk_scene_commit; only a committed scene
 * renders, and a committed scene takes no more geometry, materials or
 * lights. Materials and lights take named parameters with the type names
 * and parameter names of the JSON scene format (docs/scene-format.md) and
 * go through the same code as the JSON reader, so they are checked with
 * the same words: a message names the scene and the thing ("box: material
 * "white": kd: colour components must not be negative") where the reader
 * names a file line. A parameter the type does not have is the one
 * warning ("...: NAME: unknown parameter ignored", through the context's
 * warning callback) and is ignored. Every error is latched in the context
 * and returned; a call that fails adds nothing. */

/* Named parameter values: the public face of the readers' parameter
 * dictionary. A name set twice keeps the last value. Values are checked
 * when a creator reads them (non-finite numbers, ranges), not when set. */
typedef struct pk_params pk_params;
PK_API pk_status pk_params_create(pk_context *ctx, pk_params **out);
PK_API void pk_params_destroy(pk_params *params);
/* Removes every value (the list can describe the next thing). */
PK_API void pk_params_clear(pk_params *params);
PK_API pk_status pk_params_set_float(pk_params *params, const char *name, float value);
/* n numbers (a colour is 3, a 2D scale 2). */
PK_API pk_status pk_params_set_floats(pk_params *params, const char *name, const float *values, size_t n);
PK_API pk_status pk_params_set_rgb(pk_params *params, const char *name, float r, float g, float b);
PK_API pk_status pk_params_set_int(pk_params *params, const char *name, int value);
PK_API pk_status pk_params_set_bool(pk_params *params, const char *name, int value);
PK_API pk_status pk_params_set_string(pk_params *params, const char *name, const char *value);

/* An empty scene named name (for messages; NULL: "scene"): material 0 is
 * the default (grey diffuse), no geometry, no camera (one is framed on the
 * bounds unless pk_scene_set_camera gives one). */
PK_API pk_status pk_scene_create(pk_context *ctx, const char *name, pk_scene **out);

/* Adds a material named name (non-empty; a later one of the same name
 * hides the earlier from lookups by name) and returns its number in
 * *index. type: a JSON material type ("diffuse", "conductor",
 * "dielectric", "plastic", "metallic_roughness", "emitter", "two_sided",
 * "interface"), or NULL for the OBJ/MTL record (kd, ks, ke, tf, ka, ns, ni,
 * d, illum, two_sided). params may be NULL (the defaults). Textures, nested
 * materials ("bsdf") and media ("interior", "exterior") are not taken here
 * yet (docs/scene-api.md). */
PK_API pk_status pk_scene_add_material(pk_context *ctx, pk_scene *scene, const char *name, const char *type,
                                       const pk_params *params, uint32_t *index);

/* A triangle mesh. positions: npositions xyz triples; indices: ntriangles
 * index triples (< npositions), counter-clockwise seen from the front;
 * normals and uvs: one xyz (uv) per position, or NULL. transform: row-major,
 * transform_rows 3 (a 3x4 affine matrix) or 4 (4x4, last row 0 0 0 1), or
 * NULL for none; it places the positions (and the normals by its inverse
 * transpose). material: a number from pk_scene_add_material, or 0. */
typedef struct pk_mesh_desc {
    const float *positions;
    size_t npositions;
    const uint32_t *indices;
    size_t ntriangles;
    const float *normals;
    const float *uvs;
    const float *transform;
    int transform_rows;
    uint32_t material;
} pk_mesh_desc;

/* Adds the mesh (checked: counts, indices, finite numbers, a transform
 * that is affine and not singular). Between pk_scene_begin_object and
 * pk_scene_end_object it becomes part of the object instead of the world. */
PK_API pk_status pk_scene_add_mesh(pk_context *ctx, pk_scene *scene, const pk_mesh_desc *mesh);
/* A sphere (radius > 0, world space). */
PK_API pk_status pk_scene_add_sphere(pk_context *ctx, pk_scene *scene, const float center[3], float radius,
                                     uint32_t material);
/* A light of the JSON scene's "lights": type "point" (position), "spot"
 * (position, direction, outer_angle, inner_angle) or "distant" (direction
 * of travel); all take intensity (a number, or 3 with pk_params_set_rgb)
 * and color. Area lights are meshes with an emitting material. */
PK_API pk_status pk_scene_add_light(pk_context *ctx, pk_scene *scene, const char *type, const pk_params *params);

/* Objects: the meshes added between begin and end become one object (in
 * the space they were given in), drawn only where pk_scene_add_instance
 * places it. Objects do not nest. *object numbers the object. */
PK_API pk_status pk_scene_begin_object(pk_context *ctx, pk_scene *scene);
PK_API pk_status pk_scene_end_object(pk_context *ctx, pk_scene *scene, uint32_t *object);
/* Places object by transform (row-major, transform_rows 3 or 4, as in
 * pk_mesh_desc; NULL: where it was defined); its triangles keep their own
 * materials. */
PK_API pk_status pk_scene_add_instance(pk_context *ctx, pk_scene *scene, uint32_t object, const float *transform,
                                       int transform_rows);

/* Ends building: flattens or keeps instances, finds the emitters,
 * degenerate triangles and bounds. PK_ERR_EMPTY_SCENE when nothing can be
 * hit; an object still open is an error. A committed scene renders
 * (pk_render, pk_renderer_create); committing it again does nothing. */
PK_API pk_status pk_scene_commit(pk_context *ctx, pk_scene *scene);

/* ---- images ------------------------------------------------------------ */

/* Linear RGB float image, rows top to bottom. */
typedef struct pk_image pk_image;

PK_API pk_status pk_image_create(pk_context *ctx, int width, int height, pk_image **out);
PK_API void pk_image_destroy(pk_image *img);
PK_API int pk_image_width(const pk_image *img);
PK_API int pk_image_height(const pk_image *img);
/* 3 floats per pixel; owned by img. */
PK_API float *pk_image_pixels(pk_image *img);
PK_API const float *pk_image_pixels_const(const pk_image *img);
/* Reads an image file (PNG, JPEG, OpenEXR, Radiance .hdr, PFM; told by its
 * first bytes) as linear RGB: 8-bit files are decoded from sRGB, grey is
 * copied to the three channels, alpha dropped. layer (NULL: the image
 * itself) reads the channels LAYER.R, LAYER.G, LAYER.B of an OpenEXR file,
 * as --aov writes them ("albedo", "normal"). */
PK_API pk_status pk_image_read(pk_context *ctx, const char *path, const char *layer, pk_image **out);
/* Writes by extension (any case):
 *   .png  8-bit sRGB, through the tone curve below;
 *   .pfm  linear float RGB, the values as they are;
 *   .exr  OpenEXR: linear 32-bit float channels R, G, B, the values as they
 *         are (bit for bit), scanlines, ZIP compression.
 * The image goes to a temporary file in the same folder that is renamed into
 * place, so an existing file is only ever replaced by a complete image, and
 * no temporary file is left behind when the write fails. Errors are latched
 * as "path: what is wrong". Same as pk_image_write_ex with wo NULL. */
PK_API pk_status pk_image_write(pk_context *ctx, const pk_image *img, const char *path);

/* Options of pk_image_write_ex; pk_write_options_init sets the defaults.
 *
 * exposure_ev: PNG only. Each linear value v becomes v * 2^exposure_ev
 * before the tone curve; 0 (the default) leaves it unchanged, +1 doubles,
 * -1 halves. A finite number in [-PK_MAX_EXPOSURE_EV, PK_MAX_EXPOSURE_EV].
 * HDR outputs (.pfm, .exr) hold the renderer's linear values unscaled,
 * whatever the exposure, as pbrt and Mitsuba write theirs: exposure is a
 * choice made when viewing or converting them.
 *
 * The PNG tone curve ("clamp"): x = v * 2^exposure_ev (in float); x <= 0
 * or NaN gives 0, x >= 1 gives 255; otherwise the sRGB transfer function
 * s = 12.92 x (x <= 0.0031308) or 1.055 x^(1/2.4) - 0.055, and the byte is
 * floor(255 s + 0.5). Values above 1 are clipped, not compressed. */
#define PK_MAX_EXPOSURE_EV 20

/* Tone curves of 8-bit outputs (pk_write_options.tonemap), applied to the
 * linear values after the exposure and before the sRGB encoding:
 *   PK_TONEMAP_CLAMP        values above 1 are clipped (the default);
 *   PK_TONEMAP_AGX          Blender's AgX (its base look): the colour in
 *                           Rec.2020 through AgX's inset matrix, log2 of
 *                           x / 0.18 over [-10, +6.5] stops, AgX's sigmoid
 *                           (slope 2.4 at middle grey, toe and shoulder
 *                           powers 1.5), decoded by the 2.4 power, the
 *                           outset matrix, back to Rec.709;
 *   PK_TONEMAP_PBR_NEUTRAL  Khronos PBR Neutral: colours whose components
 *                           lie in [0.08, 0.8] come out as they went in,
 *                           less 0.04; brighter ones are compressed toward
 *                           white;
 *   PK_TONEMAP_ACES         Stephen Hill's fit of ACES's RRT and sRGB ODT
 *                           (input matrix, rational curve, output matrix).
 * Each maps 0 to 0 and is monotonic along the grey axis. */
enum { PK_TONEMAP_CLAMP = 0, PK_TONEMAP_AGX, PK_TONEMAP_PBR_NEUTRAL, PK_TONEMAP_ACES, PK_TONEMAP_COUNT };
/* "clamp", "agx", "pbr-neutral", "aces" -> PK_TONEMAP_*; -1 when unknown. */
PK_API int pk_tonemap_parse(const char *name);
/* The name of a PK_TONEMAP_* ("unknown" for any other number). */
PK_API const char *pk_tonemap_name(int tonemap);

typedef struct pk_write_options {
    float exposure_ev;
    /* PNG only: PK_TONEMAP_* (default PK_TONEMAP_CLAMP). HDR outputs hold
     * the linear values, untouched. */
    int tonemap;
    /* Coverage (NULL: opaque): an image of the same size whose first
     * channel of each pixel is its alpha in [0, 1] (a render's
     * PK_AOV_ALPHA). The image is then premultiplied colour, as a render with
     * pk_render_options.transparent gives it. PNG becomes RGBA, its colour
     * divided by alpha (PNG is not premultiplied; 0 where alpha is 0) before
     * the exposure and the tone curve; OpenEXR gets a channel A beside R, G,
     * B, which stay premultiplied (OpenEXR's convention); PFM has no alpha
     * and refuses it. */
    const pk_image *alpha;
    /* .exr only: more images of the same size written into the same file as
     * layers, channels "NAME.R", "NAME.G", "NAME.B" (the AOVs). Other formats
     * refuse layers. */
    size_t nlayers;
    const pk_image *const *layers;
    const char *const *layer_names;
} pk_write_options;

PK_API void pk_write_options_init(pk_write_options *wo);
/* pk_image_write with options; wo NULL means the defaults. An exposure out
 * of range is PK_ERR_INVALID_ARGUMENT (nothing is written). */
PK_API pk_status pk_image_write_ex(pk_context *ctx, const pk_image *img, const char *path,
                                   const pk_write_options *wo);

/* ---- films: sums of samples, merged and resolved ------------------------ */

/* A film holds, per pixel, the sum of the samples rendered there (linear RGB,
 * 3 floats) and their count. Renders add into a film; films of the same size
 * merge (from threads, processes or machines); resolving divides each sum by
 * its count (pixels without samples are black). Merging films whose pixels
 * come from one film each (disjoint regions, the usual case) is exact, so
 * any order of merges gives the same bits. */
typedef struct pk_film pk_film;

PK_API pk_status pk_film_create(pk_context *ctx, int width, int height, pk_film **out);
/* A film that also holds the AOVs of the mask aovs (PK_AOV_*). */
PK_API pk_status pk_film_create_aovs(pk_context *ctx, int width, int height, unsigned aovs, pk_film **out);
PK_API unsigned pk_film_aovs(const pk_film *film);
/* The AOV (one PK_AOV_* the film holds) as a new image: per-pixel means;
 * depth and heatmap in all three channels. */
PK_API pk_status pk_film_resolve_aov(pk_context *ctx, const pk_film *film, unsigned aov, pk_image **out);
PK_API void pk_film_destroy(pk_film *film);
PK_API int pk_film_width(const pk_film *film);
PK_API int pk_film_height(const pk_film *film);
/* Sets every sum and count to zero. */
PK_API void pk_film_clear(pk_film *film);
/* dst += src, pixel by pixel; PK_ERR_INVALID_ARGUMENT when sizes differ. */
PK_API pk_status pk_film_merge(pk_context *ctx, pk_film *dst, const pk_film *src);
/* The raw data, for moving films between processes: 3 floats (sum of R, G, B)
 * and one uint32_t (sample count) per pixel, rows top to bottom. */
PK_API float *pk_film_sums(pk_film *film);
PK_API uint32_t *pk_film_counts(pk_film *film);
/* The raw sums of one AOV the film holds (aov: one PK_AOV_*), as pk_film_sums:
 * 3 floats per pixel, rows top to bottom, over the samples pk_film_counts
 * counts; NULL when the film does not hold it. */
PK_API float *pk_film_aov_sums(pk_film *film, unsigned aov);
/* A new image of the film's size: sum / count per pixel (0 where count is 0
 * or the mean is not finite). */
PK_API pk_status pk_film_resolve(pk_context *ctx, const pk_film *film, pk_image **out);

/* ---- rendering --------------------------------------------------------- */

/* A rectangle of the image in pixels: columns x .. x+width-1, rows y .. y+height-1. */
typedef struct pk_region {
    int x, y, width, height;
} pk_region;

/* A render session: the acceleration structure and the light tables are built
 * once, in pk_renderer_create, and serve every render of the session (regions,
 * passes, camera changes). The renderer borrows scene, which must stay alive
 * and unchanged until pk_renderer_destroy; ctx must outlive it. */
typedef struct pk_renderer pk_renderer;

/* opt NULL: the scene's own settings (pk_scene_get_render_options). The
 * camera is the scene's (pk_scene_get_camera). */
PK_API pk_status pk_renderer_create(pk_context *ctx, const pk_scene *scene, const pk_render_options *opt,
                                    pk_renderer **out);
PK_API void pk_renderer_destroy(pk_renderer *r);
/* The options the renderer was created with. */
PK_API void pk_renderer_get_options(const pk_renderer *r, pk_render_options *opt);
/* Changes the camera for later renders; nothing is rebuilt. */
PK_API pk_status pk_renderer_set_camera(pk_renderer *r, const pk_camera *cam);
PK_API void pk_renderer_get_camera(const pk_renderer *r, pk_camera *cam);
/* Renders the n regions (NULL, 0: the whole image) into film, which must have
 * the renderer's width and height: every pixel of the regions gets opt.spp
 * samples added to its sum and count. A pixel's value depends only on the
 * scene, the options and the pixel, never on the regions, their order or the
 * threads, so that any tiling of the image, merged, equals one whole render
 * bit for bit. On PK_ERR_CANCELLED the film holds the tiles that finished. */
PK_API pk_status pk_renderer_render(pk_renderer *r, const pk_region *regions, size_t n, pk_film *film);
/* Progressive rendering: later renders take the samples of pass `pass`,
 * sample numbers pass * spp .. pass * spp + spp - 1 of every pixel (default 0),
 * so that rendering passes 0..k-1 into one film equals one render of k * spp
 * samples' worth of independent samples (the path tracer's sampler, the
 * Whitted integrator's random numbers), and any pass can be rendered anywhere. */
PK_API void pk_renderer_set_pass(pk_renderer *r, uint32_t pass);
/* Statistics since pk_renderer_create: the build once, the rays, tests,
 * nodes, pixels and render time of every render added up. */
PK_API void pk_renderer_get_stats(const pk_renderer *r, pk_stats *stats);

/* Adaptive sampling: passes of opt.spp samples, each over the 16 x 16 tiles
 * of the image whose noise is still above a target. The passes alternate
 * between two halves of the samples; a tile's noise is estimated from the
 * difference of its halves' means, as the relative error of its pixels'
 * mean: sqrt(mean over the tile's pixels and channels of
 * ((a - b) / 2)^2 / (m^2 + 0.01)), a and b the halves' means, m the mean of
 * all (the 0.01 keeps dark pixels from asking for endless samples). A tile
 * stops once every pixel has min_spp samples and its noise is at most
 * `noise`, or when its pixels have max_spp; the render stops when every tile
 * has, or after `seconds`. The result depends on the scene, the options and
 * these settings only, never on the threads. */
typedef struct pk_adaptive {
    float noise;    /* the target relative error (> 0), e.g. 0.05 */
    int min_spp;    /* samples every pixel gets before its tile may stop (default 16) */
    int max_spp;    /* the most samples a pixel gets (default 1024) */
    double seconds; /* a time limit (0, the default: none) */
} pk_adaptive;
/* What an adaptive render did. */
typedef struct pk_adaptive_result {
    uint32_t passes;        /* passes rendered */
    uint64_t samples;       /* samples of all pixels */
    uint32_t min_spp, max_spp; /* the fewest and the most samples of a pixel */
    size_t tiles;           /* tiles of the image */
    size_t tiles_reached;   /* tiles that reached the target (the others hit max_spp or the time limit) */
    float noise;            /* the estimated relative error of the whole image (as above, over every pixel) */
} pk_adaptive_result;

PK_API void pk_adaptive_init(pk_adaptive *a);
/* Renders the whole image adaptively into film (which must have the
 * renderer's size; the film's own samples before the call are counted as
 * one half: pass an empty film). The renderer's pass number is left after
 * the last pass. result may be NULL. On PK_ERR_CANCELLED the film holds
 * the samples of the passes that finished. */
PK_API pk_status pk_renderer_render_adaptive(pk_renderer *r, const pk_adaptive *a, pk_film *film,
                                             pk_adaptive_result *result);

/* What lies under a point of the image (pk_renderer_pick). */
typedef struct pk_pick {
    int hit;              /* 1: the ray hit a surface; 0: it left the scene (nothing else is set) */
    float t;              /* distance from the ray's origin to the hit, along the ray */
    float distance;       /* the same along the view direction: what pk_camera.focus_distance wants */
    float position[3];    /* the hit point, world space */
    float normal[3];      /* the shading normal there, facing the camera */
    uint32_t prim;        /* the primitive hit, numbered as pk_hit.prim */
    const char *material; /* the material's name ("" when it has none); owned by the scene */
} pk_pick;

/* Traces the ray through the point (x, y) of the image (pixels of the
 * renderer's width and height, (0, 0) the top-left corner, pixel (px, py)
 * covering px..px+1, py..py+1; a pixel's centre is px + 0.5) from the
 * centre of the lens of cam (NULL: the renderer's camera), through holes
 * of cut-out materials, and fills *out. Only reads what the renderer built
 * once, so it may run on another thread while that one renders (the
 * renderer must not be destroyed meanwhile). PK_ERR_INVALID_ARGUMENT when
 * (x, y) is outside the image or cam is not a valid camera; nothing is
 * latched in the renderer's context. */
PK_API pk_status pk_renderer_pick(const pk_renderer *r, const pk_camera *cam, double x, double y, pk_pick *out);

/* One call: a renderer, a film of the whole image and its resolved image
 * (*out, owned by the caller). opt NULL: the scene's settings. stats may be
 * NULL. On PK_ERR_CANCELLED *out still holds the partial image. */
PK_API pk_status pk_render(pk_context *ctx, const pk_scene *scene, const pk_render_options *opt,
                           pk_image **out, pk_stats *stats);

/* ---- denoising ---------------------------------------------------------- */

/* The denoiser runs Intel Open Image Denoise's trained network (a U-Net,
 * weights under Apache-2.0) on the CPU through oneDNN (libdnnl.so.2, loaded
 * at run time; config key dnnl.library). It takes a noisy HDR colour image
 * and, when present, the albedo and normal AOVs of the same render
 * (PK_AOV_ALBEDO, PK_AOV_NORMAL) and returns a clean colour image. The
 * weights are OIDN's .tza files, which `make weights` fetches and `make
 * install` installs; a file whose SHA-256 is not one of OIDN 2.3's is
 * refused. */
typedef enum pk_denoise_quality {
    PK_DENOISE_HIGH = 0,     /* OIDN's default network */
    PK_DENOISE_FAST = 1      /* the small network: about 1.6x faster in all, a little less sharp */
} pk_denoise_quality;

typedef struct pk_denoise_options {
    /* A folder holding the weights (rt_hdr_alb_nrm.tza ...), or one .tza
     * file; NULL: PK_DENOISE_WEIGHTS_DIR of the installed library. */
    const char *weights;
    pk_denoise_quality quality;
    int threads;        /* 0: every processor */
    float input_scale;  /* the colour is multiplied by it before the network; 0: automatic exposure */
    int clean_aux;      /* non-zero: the albedo and normal are noise-free (many samples, or no depth of field
                         * and motion blur): the network made for clean auxiliary images */
    int tile_size;      /* the image is denoised in tiles of at most this side (pixels, a
                         * multiple of 16, >= 64) that overlap; 0: 1024 */
    int tile_overlap;   /* overlap of tiles (multiple of 16); 0: 96, half the network's reach */
} pk_denoise_options;

PK_API void pk_denoise_options_init(pk_denoise_options *opt);

/* A denoiser keeps its networks and buffers between images (one thread at a
 * time). opt NULL: the defaults; opt->weights is copied. */
typedef struct pk_denoiser pk_denoiser;
PK_API pk_status pk_denoiser_create(pk_context *ctx, const pk_denoise_options *opt, pk_denoiser **out);
PK_API void pk_denoiser_destroy(pk_denoiser *d);
/* out (same size as color) = color denoised. albedo and normal may be NULL
 * (normal only with albedo); they must have color's size. Pixels that are
 * not finite or negative are taken as 0 (one warning says how many). */
PK_API pk_status pk_denoiser_run(pk_denoiser *d, const pk_image *color, const pk_image *albedo,
                                 const pk_image *normal, pk_image *out);
/* Seconds, bytes of network buffers and floating-point operations of the last run. */
PK_API void pk_denoiser_last_run(const pk_denoiser *d, double *seconds, size_t *bytes, double *flops);
/* One call: a denoiser, one run, *out a new image owned by the caller. */
PK_API pk_status pk_denoise(pk_context *ctx, const pk_denoise_options *opt, const pk_image *color,
                            const pk_image *albedo, const pk_image *normal, pk_image **out);
/* Whether the weights the options name are there and oneDNN loads: PK_OK,
 * or an error whose message says what is missing and how to get it. */
PK_API pk_status pk_denoise_check(pk_context *ctx, const pk_denoise_options *opt);

/* ---- rays against an acceleration structure (benchmarks, tools) --------- */

/* Same layout as a record of a .rays file (32 bytes). */
typedef struct pk_ray {
    float org[3];
    float tmin;
    float dir[3];
    float tmax;
} pk_ray;

/* Same layout as a record of a .hits file (16 bytes). prim numbers the
 * triangles in file order, then the spheres; PK_NO_HIT on a miss (t = +inf).
 * Hit point = (1-u-v)*v0 + u*v1 + v*v2. */
typedef struct pk_hit {
    float t;
    uint32_t prim;
    float u, v;
} pk_hit;

#define PK_NO_HIT 0xFFFFFFFFu

typedef struct pk_accel pk_accel;

typedef struct pk_accel_info {
    const char *name;
    double build_ms;
    size_t nodes, leaves, primitives;
    size_t bytes;     /* memory held by the structure */
    double sah_cost;  /* 0 when not computed */
} pk_accel_info;

typedef struct pk_trace_counters {
    uint64_t intersection_tests, nodes_visited;
} pk_trace_counters;

enum {
    PK_TRACE_ANY_HIT = 1u,  /* occlusion only: t of some hit, or +inf */
    PK_TRACE_COHERENT = 2u  /* rays come in coherent groups: use packets */
};

/* Builds an accelerator over the scene's triangles and spheres with up to
 * threads threads (0 = all). The accel borrows nothing from scene; ctx must
 * outlive it (it allocates through ctx's allocator). */
PK_API pk_status pk_accel_create(pk_context *ctx, const pk_scene *scene, pk_accel_kind kind,
                                 int threads, pk_accel **out);
PK_API void pk_accel_destroy(pk_accel *accel);
PK_API void pk_accel_get_info(const pk_accel *accel, pk_accel_info *info);
/* The SIMD instruction set of the CPU kernels accel traces with, where the
 * library chose one for this CPU: "avx512" or "avx2" for PK_ACCEL_BVH
 * (AVX-512 where the CPU has it; the config key cpu.isa=avx2, read when the
 * accelerator is created, forces AVX2: pk_context_set_config).
 * Both find the same hits. NULL for the other accelerators. */
PK_API const char *pk_accel_isa(const pk_accel *accel);
/* Traces n rays with up to threads threads; hits[i] answers rays[i].
 * counters may be NULL (nothing is counted then). A device accelerator
 * (PK_ACCEL_CUDA) that fails (a kernel error) latches the error in the
 * accelerator's context and leaves every hit a miss. */
PK_API void pk_accel_trace(const pk_accel *accel, const pk_ray *rays, pk_hit *hits, size_t n,
                           int threads, unsigned flags, pk_trace_counters *counters);

/* Where a device accelerator spends its time, in milliseconds, and the
 * device memory it holds. */
typedef struct pk_accel_device_info {
    char device[128];         /* the device's name */
    double upload_ms;         /* copying the structure to the device (at pk_accel_create) */
    size_t structure_bytes;   /* device memory held by the structure */
    size_t device_bytes;      /* all device memory held (structure, ray and hit buffers) */
    /* of the last pk_accel_trace: */
    double rays_upload_ms;    /* rays to the device */
    double kernel_ms;         /* the traversal kernel alone */
    double download_ms;       /* hits back from the device */
} pk_accel_device_info;

/* 1 and *info filled when accel runs on a device, else 0. */
PK_API int pk_accel_get_device_info(const pk_accel *accel, pk_accel_device_info *info);

#ifdef __cplusplus
}
#endif
#endif /* PAPRSEK_H */
