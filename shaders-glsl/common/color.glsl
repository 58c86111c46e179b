// Colour helpers shared by every pass.

// IEC 61966-2-1 (sRGB) transfer function, linear -> encoded.
vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
