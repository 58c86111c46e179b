// Equirectangular lookup, the convention of scene/env/map.rs: +Y up,
// dir = (sinθ sinφ, cosθ, −sinθ cosφ), u = φ/2π + 1/2, v = θ/π.
const float PI = 3.14159265358979;

vec2 equirect_uv(vec3 d) {
    d = normalize(d);
    float theta = acos(clamp(d.y, -1.0, 1.0));
    float phi = atan(d.x, -d.z);
    return vec2(phi / (2.0 * PI) + 0.5, theta / PI);
}

// Rotates a world direction into the environment map's frame (map turned by `angle` about +Y).
vec3 env_dir(vec3 d, float angle) {
    float c = cos(angle), s = sin(angle);
    return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// The inverse of equirect_uv.
vec3 equirect_dir(vec2 uv) {
    float theta = uv.y * PI;
    float phi = (uv.x - 0.5) * 2.0 * PI;
    return vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}
