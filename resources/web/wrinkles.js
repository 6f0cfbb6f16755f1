// wrinkles.js: Wrinkle Studio's wrinkles on a glTF face loaded by three.js (r160 and later).
//
//   import { attachWrinkles } from './wrinkles.js';
//   const gltf = await new GLTFLoader().loadAsync('face.glb');
//   scene.add(gltf.scene);
//   const wrinkles = await attachWrinkles(gltf);   // technique 1; wrinkles.technique = 't2'
//
// An ES module without a build step; it imports 'three' (an import map names it). It reads the
// studio's set-up from the file (extras.wrinklePlayer, the web page's own format), patches the
// face's MeshStandardMaterial (onBeforeCompile) and, before every draw of the face, turns its
// morphTargetInfluences into the wrinkles:
// - technique 1 (areas): each area's activation is its own value plus gain * curve(weight) of
//   its linked poses (the web page's code, below); the normal map is blended toward each
//   wrinkled map by the sum of mask * activation of the areas that reveal it;
// - technique 2 (wrinkle direction vectors): per vertex, the strongest of up to four areas'
//   visibility of the vertex's motion (its morphed minus its rest position) inside the area's
//   cone; the vectors ride in a float data texture read by vertex index (the face has more
//   vertex attributes than WebGL2's 16).
// The poses' changes of tangent (the file's TANGENT morph targets, which three.js does not morph)
// are added in the vertex shader, so the normal maps turn with the skin as in the studio. Where
// the studio blends shaded colours, three.js shades once: the normals are blended (the studio's
// "normal" blend), so the wrinkles show in the same places with a little less contrast. Any lit
// material with a normal map takes the patch (GLTFLoader makes a MeshStandardMaterial).
import * as THREE from 'three';

// {{ACTIVATIONS}}

const KEY = 'wrinklePlayer';
export const TECHNIQUES = { none: 0, t1: 1, t2: 2 };
const TEXELS = 7; // per vertex: 4 slots' direction and length, cones, maps, skin
const WIDTH = 4096; // of the vertex data texture

// The pose weights in the player's pose order, from the mesh's morph targets (by name).
export function poseWeights(player, mesh) {
  const names = mesh.morphTargetDictionary || {};
  const influences = mesh.morphTargetInfluences || [];
  return player.poses.map((name) => (name in names ? influences[names[name]] || 0 : 0));
}

// An array of the file's (a face without areas has no technique-1 arrays).
function array(arrays, name) {
  return (arrays[name] || { data: new Float32Array(0) }).data;
}

// Per morph target, the share of its weight its pose's onset holds back from technique 2:
// w - onset_weight(w) (core/wrinkles/response.py), 0 without an onset.
export function heldBack(player, mesh) {
  const names = mesh.morphTargetDictionary || {};
  const held = new Float32Array((mesh.morphTargetInfluences || []).length);
  const weights = poseWeights(player, mesh);
  player.poses.forEach((name, p) => {
    const onset = (player.onsets || [])[p] || 0;
    const w = weights[p];
    if (name in names && onset > 0) held[names[name]] = w - Math.max((w - onset) / (1 - onset), 0);
  });
  return held;
}

// Technique 1's activations of the face as the mesh is posed now.
export function activationsOf(player, arrays, mesh) {
  return wrinkleActivations(player.links, array(arrays, 't1.base'), array(arrays, 't1.shown'),
    poseWeights(player, mesh));
}

async function readArrays(parser, index) {
  const entries = await Promise.all(Object.entries(index).map(async ([name, spec]) => {
    const buffer = await parser.getDependency('bufferView', spec.bufferView);
    const count = spec.shape.reduce((a, b) => a * b, 1);
    return [name, { data: new Float32Array(buffer, 0, count), shape: spec.shape }];
  }));
  return Object.fromEntries(entries);
}

function imageTexture(parser, name) {
  const json = parser.json;
  const image = (json.images || []).findIndex((spec) => spec.name === name);
  const texture = (json.textures || []).findIndex((spec) => spec.source === image);
  if (image < 0 || texture < 0) {
    throw new Error(`wrinkles.js: the file holds no texture of the image '${name}'`);
  }
  return parser.getDependency('texture', texture);
}

// The masks, one layer each, as an 8-bit array texture (a shader may sample only 16 textures).
async function maskArray(parser, names) {
  const textures = await Promise.all(names.map((name) => imageTexture(parser, name)));
  const width = textures.length ? textures[0].image.width : 1;
  const height = textures.length ? textures[0].image.height : 1;
  const data = new Uint8Array(width * height * Math.max(textures.length, 1));
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  const context = canvas.getContext('2d', { willReadFrequently: true });
  textures.forEach((texture, layer) => {
    context.clearRect(0, 0, width, height);
    context.drawImage(texture.image, 0, 0, width, height);
    const rgba = context.getImageData(0, 0, width, height).data;
    const out = data.subarray(layer * width * height, (layer + 1) * width * height);
    for (let i = 0; i < out.length; ++i) out[i] = rgba[4 * i];
    texture.dispose();
  });
  const masks = new THREE.DataArrayTexture(data, width, height, Math.max(textures.length, 1));
  masks.format = THREE.RedFormat;
  masks.minFilter = THREE.LinearMipmapLinearFilter;
  masks.magFilter = THREE.LinearFilter;
  masks.generateMipmaps = true;
  masks.needsUpdate = true;
  return masks;
}

// Technique 2's slots and the skin weight, TEXELS texels per vertex, read by gl_VertexID.
function vertexTexture(arrays) {
  const count = arrays.skin.data.length;
  const rows = Math.max(Math.ceil((count * TEXELS) / WIDTH), 1);
  const data = new Float32Array(WIDTH * rows * 4);
  const dirs = arrays['wdv.dirs'].data, cones = arrays['wdv.cones'].data;
  const maps = arrays['wdv.maps'].data, skin = arrays.skin.data;
  for (let v = 0; v < count; ++v) {
    const at = v * TEXELS * 4;
    data.set(dirs.subarray(16 * v, 16 * v + 16), at);
    data.set(cones.subarray(4 * v, 4 * v + 4), at + 16);
    data.set(maps.subarray(4 * v, 4 * v + 4), at + 20);
    data[at + 24] = skin[v];
  }
  const texture = new THREE.DataTexture(data, WIDTH, rows, THREE.RGBAFormat, THREE.FloatType);
  texture.needsUpdate = true;
  return texture;
}

const VERTEX_HEAD = /* glsl */ `
uniform highp sampler2D wrVertices;
uniform highp sampler2D wrTangents;
uniform int wrTangentTargets;
uniform int wrVertexCount;
uniform int wrTechnique;
uniform float wrExpression;
uniform bool wrScaleFree;
#if defined(USE_MORPHTARGETS) && defined(MORPHTARGETS_TEXTURE)
uniform float wrHeld[MORPHTARGETS_COUNT]; // per morph target: what its pose's onset holds back
#endif
varying vec4 vWrWeights;
varying float vWrSkin;
vec4 wrTexel(int i) {
  int w = textureSize(wrVertices, 0).x;
  return texelFetch(wrVertices, ivec2(i % w, i / w), 0);
}
// The studio's wdv_visibility (shaders/face.vert): per wrinkled map, the strongest slot's
// clamp(|delta| * (1 - alpha / theta) * k, 0, 1) inside its cone.
vec4 wrVisibility(vec3 delta, int first) {
  float len = length(delta);
  vec4 w = vec4(0.0);
  if (len <= 0.0) return w;
  vec4 cones = wrTexel(first + 4), maps = wrTexel(first + 5);
  for (int s = 0; s < 4; ++s) {
    vec4 d = wrTexel(first + s);
    float theta = cones[s];
    if (d.w <= 0.0 || theta <= 0.0) continue;
    float alpha = acos(clamp(dot(delta, d.xyz) / len, -1.0, 1.0));
    if (alpha >= theta) continue;
    float magnitude = wrScaleFree ? len / d.w : len;
    int m = int(maps[s]);
    w[m] = max(w[m], clamp(magnitude * (1.0 - alpha / theta) * wrExpression, 0.0, 1.0));
  }
  return w;
}
`;

// Technique 2 measures the motion from a rest moved by what each pose's onset holds back of
// it (the studio's render/wrinkle_drive.py), so no wrinkle shows before the onset.
const VERTEX_BODY = /* glsl */ `
#include <morphtarget_vertex>
vec3 wrRest = position;
#if defined(USE_MORPHTARGETS) && defined(MORPHTARGETS_TEXTURE)
for (int k = 0; k < MORPHTARGETS_COUNT; ++k) {
  if (wrHeld[k] != 0.0) wrRest += wrHeld[k] * getMorph(gl_VertexID, k, 0).xyz;
}
#endif
vWrSkin = wrTexel(gl_VertexID * ${TEXELS} + 6).x;
vWrWeights = wrTechnique == 2 ? wrVisibility(transformed - wrRest, gl_VertexID * ${TEXELS})
                              : vec4(0.0);
`;

function fragmentHead(maps) {
  const samplers = maps.map((_, m) => `uniform sampler2D wrMap${m};`).join('\n');
  const fetches = maps.map((_, m) => `  if (m == ${m}) return wrUnpack(texture2D(wrMap${m}, uv).xy);`)
    .join('\n');
  return /* glsl */ `
#define WR_MAPS ${maps.length}
uniform int wrTechnique;
uniform highp sampler2DArray wrMasks;
uniform highp sampler2D wrActivations;
${samplers}
varying vec4 vWrWeights;
varying float vWrSkin;
vec3 wrUnpack(vec2 xy) {
  vec2 n = xy * 2.0 - 1.0;
  return vec3(n, sqrt(max(1.0 - dot(n, n), 0.0)));
}
vec3 wrMapNormal(int m, vec2 uv) {
${fetches}
  return vec3(0.0, 0.0, 1.0);
}
// Per wrinkled map: technique 1's sum of mask * activation over the areas revealing it
// (shaders/face.frag, T1_DIRECT), technique 2's visibility from the vertices.
vec4 wrWeights(vec2 uv) {
  if (wrTechnique == 2) return vWrWeights;
  vec4 s = vec4(0.0);
  if (wrTechnique == 1) {
    int areas = textureSize(wrMasks, 0).z;
    for (int i = 0; i < areas; ++i) {
      vec2 a = texelFetch(wrActivations, ivec2(i, 0), 0).rg;
      if (a.x > 0.0) s[int(a.y)] += texture(wrMasks, vec3(uv, float(i))).r * a.x;
    }
  }
  return clamp(s, 0.0, 1.0);
}
`;
}

const FRAGMENT_BODY = /* glsl */ `
#ifdef USE_NORMALMAP_TANGENTSPACE
  vec4 wrW = wrWeights(vNormalMapUv) * vWrSkin;
  float wrTotal = wrW.x + wrW.y + wrW.z + wrW.w;
  if (wrTotal > 1.0) {
    wrW /= wrTotal;
    wrTotal = 1.0;
  }
  vec3 mapN = wrUnpack(texture2D(normalMap, vNormalMapUv).xy);
  mapN.xy *= normalScale;
  vec3 wrSum = normalize(tbn * mapN) * (1.0 - wrTotal);
  for (int m = 0; m < WR_MAPS; ++m) {
    if (wrW[m] > 0.0) {
      vec3 t = wrMapNormal(m, vNormalMapUv);
      t.xy *= normalScale;
      wrSum += wrW[m] * normalize(tbn * t);
    }
  }
  normal = normalize(wrSum);
#else
#include <normal_fragment_maps>
#endif
`;

// three.js morphs the normals, not the tangents: each pose's change of tangent (the file's
// TANGENT morph targets, the studio's own at each pose) added here by the same influences, and
// the tangent made perpendicular to the posed normal again, as the web page does, so a pose's
// normal maps turn with its skin as in the studio.
const TANGENT_BODY = /* glsl */ `
#include <morphnormal_vertex>
#ifdef USE_TANGENT
#if defined(USE_MORPHTARGETS) && defined(MORPHTARGETS_TEXTURE)
  for (int k = 0; k < MORPHTARGETS_COUNT; ++k) {
    float w = morphTargetInfluences[k];
    if (w != 0.0 && k < wrTangentTargets) {
      int i = k * wrVertexCount + gl_VertexID;
      int width = textureSize(wrTangents, 0).x;
      objectTangent += w * texelFetch(wrTangents, ivec2(i % width, i / width), 0).xyz;
    }
  }
#endif
  vec3 wrNormal = normalize(objectNormal);
  vec3 wrTangent = objectTangent - dot(objectTangent, wrNormal) * wrNormal;
  if (dot(wrTangent, wrTangent) > 1e-12) objectTangent = normalize(wrTangent);
#endif
`;

// The face's TANGENT morph targets (one texel per vertex and target), null when it has none.
async function tangentTargets(parser, mesh) {
  const where = parser.associations.get(mesh);
  const targets = where ? parser.json.meshes[where.meshes].primitives[where.primitives].targets
    : null;
  if (!targets || !targets.length || !targets.every((t) => 'TANGENT' in t)) return null;
  const deltas = await Promise.all(targets.map((t) => parser.getDependency('accessor',
    t.TANGENT)));
  const count = deltas[0].count;
  const rows = Math.max(Math.ceil((count * deltas.length) / WIDTH), 1);
  const data = new Float32Array(WIDTH * rows * 4);
  deltas.forEach((delta, k) => {
    for (let v = 0; v < count; ++v) {
      const at = 4 * (k * count + v);
      data[at] = delta.getX(v);
      data[at + 1] = delta.getY(v);
      data[at + 2] = delta.getZ(v);
    }
  });
  const texture = new THREE.DataTexture(data, WIDTH, rows, THREE.RGBAFormat, THREE.FloatType);
  texture.needsUpdate = true;
  return { texture, targets: deltas.length, count };
}

function patch(material, uniforms, maps) {
  material.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, uniforms);
    shader.vertexShader = VERTEX_HEAD + shader.vertexShader
      .replace('#include <morphnormal_vertex>', TANGENT_BODY)
      .replace('#include <morphtarget_vertex>', VERTEX_BODY);
    shader.fragmentShader = fragmentHead(maps) + shader.fragmentShader
      .replace('#include <normal_fragment_maps>', FRAGMENT_BODY);
  };
  material.customProgramCacheKey = () => `wrinkle-studio-${maps.length}`;
  material.needsUpdate = true;
}

// The face: the mesh whose morph targets are the player's poses (else the first mesh).
function findFace(root, player) {
  let face = null, first = null;
  root.traverse((object) => {
    if (!object.isMesh) return;
    first = first || object;
    const names = object.morphTargetDictionary || {};
    if (!face && player.poses.length && player.poses.every((name) => name in names)) face = object;
  });
  if (!(face || first)) throw new Error('wrinkles.js: the glTF holds no mesh');
  return face || first;
}

/**
 * Attach the wrinkles to a glTF loaded by GLTFLoader. Returns a controller: `technique`
 * ('none', 't1' or 't2', settable), `mesh`, `activations()` (technique 1's, as last drawn) and
 * `update()` (done before every draw of the face; call it yourself only to read activations
 * without drawing).
 */
export async function attachWrinkles(gltf, { technique = 't1' } = {}) {
  const parser = gltf.parser;
  const player = parser.json.extras && parser.json.extras[KEY];
  if (!player) {
    throw new Error('wrinkles.js: this glTF holds no Wrinkle Studio set-up (extras.' + KEY +
      '): export it from Wrinkle Studio, and load it with GLTFLoader');
  }
  if (!(technique in TECHNIQUES)) throw new Error(`wrinkles.js: no technique '${technique}'`);
  const mesh = findFace(gltf.scene, player);
  const arrays = await readArrays(parser, player.arrays);
  const maps = await Promise.all(player.wrinkle_maps.map((name) => imageTexture(parser, name)));
  const areas = Math.max(player.areas.length, 1);
  const activationTexels = new Float32Array(4 * areas);
  const activationTexture = new THREE.DataTexture(activationTexels, areas, 1, THREE.RGBAFormat,
    THREE.FloatType);
  const tangents = await tangentTargets(parser, mesh);
  const uniforms = {
    wrTechnique: { value: TECHNIQUES[technique] },
    wrTangents: { value: tangents ? tangents.texture : null },
    wrTangentTargets: { value: tangents ? tangents.targets : 0 },
    wrVertexCount: { value: tangents ? tangents.count : 0 },
    wrHeld: { value: heldBack(player, mesh) },
    wrVertices: { value: vertexTexture(arrays) },
    wrExpression: { value: player.wdv.expression_factor },
    wrScaleFree: { value: player.wdv.scale_free },
    wrMasks: { value: await maskArray(parser, player.masks) },
    wrActivations: { value: activationTexture },
  };
  maps.forEach((texture, m) => { uniforms[`wrMap${m}`] = { value: texture }; });
  patch(mesh.material, uniforms, maps);

  let current = new Float32Array(player.areas.length);
  const areaMaps = array(arrays, 't1.maps');
  const update = () => {
    current = activationsOf(player, arrays, mesh);
    current.forEach((a, i) => {
      activationTexels[4 * i] = a;
      activationTexels[4 * i + 1] = areaMaps[i];
    });
    activationTexture.needsUpdate = true;
    uniforms.wrHeld.value = heldBack(player, mesh);
  };
  const before = mesh.onBeforeRender;
  mesh.onBeforeRender = function (...args) {
    update();
    before.apply(this, args);
  };
  update();
  return {
    mesh,
    update,
    activations: () => current.slice(),
    get technique() {
      return Object.keys(TECHNIQUES).find((k) => TECHNIQUES[k] === uniforms.wrTechnique.value);
    },
    set technique(name) {
      if (!(name in TECHNIQUES)) throw new Error(`wrinkles.js: no technique '${name}'`);
      uniforms.wrTechnique.value = TECHNIQUES[name];
    },
  };
}
