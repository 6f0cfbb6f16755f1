// Relief "displace" (GL 4.0 tessellation), shared by face.tesc and face.tese: the per-map
// wrinkle weights at a point of the surface, the same ones face.frag shades with.
// Technique 1 reads them from the composed weight texture at the point's texcoord (the renderer
// composes it for displacement even in T1_DIRECT mode); techniques 2 and strain interpolate
// the vertex shader's per-vertex weights. Both are times the skin weight (0 = not face).

#ifdef TECHNIQUE_T1
uniform sampler2D u_t1_weight;

vec4 surface_weights(vec2 texcoord, vec4 vertex_weights, float skin) {
    return textureLod(u_t1_weight, texcoord, 0.0) * skin;
}
#else
vec4 surface_weights(vec2 texcoord, vec4 vertex_weights, float skin) {
    return vertex_weights * skin;
}
#endif
