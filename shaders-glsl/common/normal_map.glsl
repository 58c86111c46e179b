// Tangent-space normal mapping. x and y decode as (255·c − 128)/127, so the
// 8-bit value 128 is exactly flat (c·2 − 1 would tilt every normal by 1/255).
vec3 map_normal(sampler2D map, vec2 uv, vec3 normal, vec4 tangent) {
    vec3 n = normalize(normal);
    vec3 t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
    vec3 b = cross(n, t) * tangent.w;
    vec3 c = texture(map, uv).xyz;
    vec3 m = vec3((c.xy * 255.0 - 128.0) / 127.0, c.z * 2.0 - 1.0);
    return normalize(m.x * t + m.y * b + m.z * n);
}

// Two-sided shading: the back of the surface is seen where the interpolated
// vertex normal lies on the far side of the triangle's plane (its edges dpdx,
// dpdy) from the camera. Not where that normal faces away from the camera: at
// a closed surface's silhouette it may, on the front.
bool seen_from_behind(vec3 vertex_normal, vec3 to_camera, vec3 dpdx, vec3 dpdy) {
    vec3 plane = cross(dpdx, dpdy);
    return dot(vertex_normal, plane) * dot(to_camera, plane) < 0.0;
}
