// The mesh's vertex buffer read as a storage buffer at binding VERTICES
// (frame::Vertex: position, normal, uv, tangent, VERTEX_FLOATS floats), and
// where the irradiance pass's compute formulation keeps each vertex's values:
// two RGBA32F texels per vertex, as many vertices a row as the image's width
// holds (skin::irradiance::VERTICES_PER_ROW sets it).
#ifdef VERTICES
layout(std430, binding = VERTICES) readonly buffer Vertices { float vertices[]; };
#endif
const uint VERTEX_FLOATS = 12u;
const uint POSITION_FLOAT = 0u;
const uint UV_FLOAT = 6u;

// The first of vertex v's two texels (position, then occluded irradiance) in
// an image `width` texels wide.
ivec2 vertex_values_texel(uint v, int width) {
    uint per_row = uint(width) / 2u;
    return ivec2(2u * (v % per_row), v / per_row);
}
