// An explicit light of frame.glsl at a point, unshadowed: directional, or a
// point light with 1/d² falloff. Needs frame.glsl.
const float POINT_REFERENCE_MM = 1000.0;   // scene::POINT_LIGHT_REFERENCE_MM

// Irradiance light i delivers at x to a surface facing it, unshadowed (mirrors
// scene::Light::at); l: the unit direction towards the light; dist: the
// distance to a point light (1 for a directional one).
vec3 light_incident(int i, vec3 x, out vec3 l, out float dist) {
    vec4 lv = frame.light_vec[i];
    vec3 e = frame.light_color[i].rgb;
    dist = 1.0;
    if (lv.w > 0.5) {
        vec3 d = lv.xyz - x;
        float d2 = max(dot(d, d), 1e-6);
        dist = sqrt(d2);
        l = d / dist;
        e *= POINT_REFERENCE_MM * POINT_REFERENCE_MM / d2;
    } else {
        l = lv.xyz;
    }
    return e;
}
