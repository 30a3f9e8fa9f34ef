/*
 * scene_record.c - the field tables of the JSON scene's record forms
 * (scene_record.h).
 */
#include "scene_record.h"

#define F(s, name, type) {#name, type, offsetof(s, name)}

const rec_field rec_material[] = {
    F(material, kd, REC_VEC3),          F(material, ks, REC_VEC3),
    F(material, ke, REC_VEC3),          F(material, tf, REC_VEC3),
    F(material, ka, REC_VEC3),          F(material, ns, REC_FLOAT),
    F(material, ni, REC_FLOAT),         F(material, d, REC_FLOAT),
    F(material, illum, REC_INT),        F(material, two_sided, REC_BOOL),
    F(material, type, REC_INT),         F(material, alpha, REC_FLOAT),
    F(material, alpha_v, REC_FLOAT),
    F(material, eta, REC_VEC3),         F(material, k, REC_VEC3),
    F(material, schlick, REC_BOOL),     F(material, beckmann, REC_BOOL),
    F(material, metallic, REC_FLOAT),   F(material, roughness, REC_FLOAT),
    F(material, transmission, REC_FLOAT), F(material, clearcoat, REC_FLOAT),
    F(material, clearcoat_roughness, REC_FLOAT), F(material, tint, REC_VEC3),
    F(material, volume, REC_BOOL),
    F(material, mix_a, REC_INT),        F(material, mix_b, REC_INT),
    F(material, amount, REC_FLOAT),
    F(material, coat_base, REC_INT),    F(material, base_alpha, REC_FLOAT),
    {"coat_thickness", REC_FLOAT, offsetof(material, layer.thickness)},
    {"coat_albedo", REC_VEC3, offsetof(material, layer.albedo)},
    {"coat_g", REC_FLOAT, offsetof(material, layer.g)},
    {"coat_maxdepth", REC_INT, offsetof(material, layer.maxdepth)},
    {"coat_nsamples", REC_INT, offsetof(material, layer.nsamples)},
    F(material, anisotropic, REC_FLOAT), F(material, ax, REC_FLOAT),
    F(material, ay, REC_FLOAT),         F(material, spec_tint, REC_FLOAT),
    F(material, sheen, REC_FLOAT),      F(material, sheen_tint, REC_FLOAT),
    F(material, flatness, REC_FLOAT),   F(material, clearcoat_gloss, REC_FLOAT),
    F(material, srate_spec, REC_FLOAT), F(material, srate_cc, REC_FLOAT),
    F(material, srate_diff, REC_FLOAT), F(material, thin, REC_BOOL),
    F(material, diff_trans, REC_FLOAT), F(material, srate_st, REC_FLOAT),
    F(material, srate_dt, REC_FLOAT),
    F(material, norm_scale, REC_FLOAT), F(material, coat_norm_scale, REC_FLOAT), F(material, blend, REC_BOOL),
    F(material, blend_alpha, REC_FLOAT), F(material, vertex_color, REC_BOOL),
    F(material, specular, REC_FLOAT),
    F(material, specular_color, REC_VEC3), F(material, sheen_color, REC_VEC3),
    F(material, sheen_roughness, REC_FLOAT), F(material, iridescence, REC_FLOAT),
    F(material, iridescence_ior, REC_FLOAT), F(material, iridescence_thickness, REC_FLOAT),
    F(material, iridescence_thickness_min, REC_FLOAT), F(material, anisotropy, REC_FLOAT),
    F(material, anisotropy_rotation, REC_FLOAT), F(material, whitted_sheen, REC_FLOAT),
};
const size_t rec_nmaterial = sizeof rec_material / sizeof rec_material[0];

const rec_field rec_texref[] = {
    {"kind", REC_U8, offsetof(tex_ref, kind)},   F(tex_ref, clamp, REC_WRAP), F(tex_ref, squared, REC_BOOL),
    F(tex_ref, s, REC_F2),                          F(tex_ref, o, REC_F2),       F(tex_ref, bm, REC_FLOAT),
    F(tex_ref, even, REC_VEC3),                     F(tex_ref, odd, REC_VEC3),   F(tex_ref, checker_scale, REC_FLOAT),
    F(tex_ref, uvset, REC_U8),
};
const size_t rec_ntexref = sizeof rec_texref / sizeof rec_texref[0];

const rec_field rec_light[] = {
    F(point_light, position, REC_VEC3), F(point_light, intensity, REC_VEC3), F(point_light, spot_dir, REC_VEC3),
    F(point_light, cos_inner, REC_FLOAT), F(point_light, cos_outer, REC_FLOAT),
    F(point_light, spot_falloff, REC_INT), F(point_light, distant, REC_BOOL),
    F(point_light, map_kind, REC_INT), F(point_light, to_light, REC_F9),
    F(point_light, proj_tan, REC_FLOAT), F(point_light, proj_sx, REC_FLOAT), F(point_light, proj_sy, REC_FLOAT),
};
const size_t rec_nlight = sizeof rec_light / sizeof rec_light[0];

const rec_field rec_env[] = {
    F(scene_environment, set, REC_BOOL),           F(scene_environment, radiance, REC_VEC3),
    F(scene_environment, map_scale, REC_FLOAT),    F(scene_environment, to_world, REC_F9),
    F(scene_environment, has_sun, REC_BOOL),       F(scene_environment, sun_dir, REC_VEC3),
    F(scene_environment, sun_radiance, REC_VEC3),  F(scene_environment, sun_angle, REC_FLOAT),
    F(scene_environment, has_sky, REC_BOOL),       F(scene_environment, sky_turbidity, REC_FLOAT),
    F(scene_environment, sky_scale, REC_FLOAT),    F(scene_environment, sky_hosek, REC_BOOL),
    F(scene_environment, sky_albedo, REC_VEC3),
};
const size_t rec_nenv = sizeof rec_env / sizeof rec_env[0];

const rec_field rec_medium[] = {
    F(medium, kind, REC_INT),  F(medium, sigma_t, REC_VEC3), F(medium, albedo, REC_VEC3),
    F(medium, le, REC_VEC3),   F(medium, g, REC_FLOAT),      F(medium, grid_to_world, REC_F16),
};
const size_t rec_nmedium = sizeof rec_medium / sizeof rec_medium[0];
