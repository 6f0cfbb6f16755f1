// Per-mesh data for the deformation passes, stored in 2-D textures row after row (the studio
// runs on OpenGL 3.3, which has no texture buffer objects in moderngl): item i of a texture
// is texel (i mod width, i div width).

ivec2 item(int i, int width) {
    return ivec2(i % width, i / width);
}

vec4 fetch(sampler2D data, int i) {
    return texelFetch(data, item(i, textureSize(data, 0).x), 0);
}

ivec4 fetch(isampler2D data, int i) {
    return texelFetch(data, item(i, textureSize(data, 0).x), 0);
}
