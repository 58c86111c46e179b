// Unit vectors as two numbers in [−1, 1]: the octahedral map (Meyer et al.
// 2010; Cigolle et al. 2014, "A Survey of Efficient Representations for
// Independent Unit Vectors", JCGT 3(2), listings 1–2).
vec2 octahedral_wrap(vec2 v) {
    return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

vec2 octahedral_encode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    return n.z >= 0.0 ? n.xy : octahedral_wrap(n.xy);
}

vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = octahedral_wrap(n.xy);
    return normalize(n);
}
