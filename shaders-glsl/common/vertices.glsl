// The mesh's vertex buffer read as a storage buffer at binding VERTICES
// (frame::Vertex: position, normal, uv, tangent, VERTEX_FLOATS floats), and
// where the irradiance pass's compute formulation keeps each vertex's values:
// two RGBA32F texels per vertex, VERTICES_PER_ROW vertices a row
// (skin::irradiance::VERTICES_PER_ROW).
#ifdef VERTICES
layout(std430, binding = VERTICES) readonly buffer Vertices { float vertices[]; };
#endif
const uint VERTEX_FLOATS = 12u;
const uint POSITION_FLOAT = 0u;
const uint UV_FLOAT = 6u;
const uint VERTICES_PER_ROW = 1024u;

// The first of vertex v's two texels (position, then occluded irradiance).
ivec2 vertex_values_texel(uint v) {
    return ivec2(2u * (v % VERTICES_PER_ROW), v / VERTICES_PER_ROW);
}
