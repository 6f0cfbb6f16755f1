// Wrinkle Studio's web player: a small WebGL2 renderer of the face with both wrinkle techniques.
// The shading is the studio's own GLSL (shaders/face.vert, face.frag, common.glsl, carried in the
// page as text and compiled here as GLSL ES 3.00); this file only does what the studio does on
// the CPU: blends the key poses (positions, normals and tangents), turns pose weights into
// technique 1's activations through the links' response curves, and keeps the camera.
'use strict';

const TECHNIQUES = { none: 'Off', t1: 'Technique 1 (areas)', t2: 'Technique 2 (WDV)' };
const UNIT = { diffuse: 0, normals: 1, more_maps: 2, masks: 3, activations: 4, tone: 5 };

function say(text) {
  document.getElementById('message').textContent = text;
}

async function inflate(text) {
  // the face's arrays: base64 of zlib data, inflated by the browser (no fetch: file:// works)
  const binary = atob(text.trim());
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Response(stream).arrayBuffer();
}

function readArrays(buffer, index) {
  const kinds = { f4: Float32Array, u4: Uint32Array, i2: Int16Array, u1: Uint8Array };
  const out = {};
  for (const [name, spec] of Object.entries(index)) {
    const count = spec.shape.reduce((a, b) => a * b, 1);
    out[name] = { data: new kinds[spec.type](buffer, spec.offset, count), shape: spec.shape };
  }
  return out;
}

// --- the query ------------------------------------------------------------------------------
function readQuery(scene) {
  const q = new URLSearchParams(location.search);
  const problems = [];
  let technique = q.get('technique') || 't2';
  if (!(technique in TECHNIQUES)) {
    problems.push(`technique=${technique}: choose none, t1 or t2`);
    technique = 't2';
  }
  const weights = new Float32Array(scene.poses.length);
  const pose = q.get('pose');
  let still = false;
  if (pose !== null) {
    still = true;
    let weight = q.has('weight') ? Number(q.get('weight')) : 1;
    if (!Number.isFinite(weight) || weight < 0 || weight > 1) {
      problems.push(`weight=${q.get('weight')}: a pose weight is between 0 and 1`);
      weight = 1;
    }
    const k = scene.poses.findIndex((p) => p.name === pose);
    if (k >= 0) weights[k] = weight;
    else if (pose !== 'neutral') problems.push(`pose=${pose}: no such key pose`);
  }
  return { technique, weights, still, bare: q.get('ui') === '0', problems };
}

// --- camera: the studio's OrbitCamera (core/mesh/camera.py) ---------------------------------
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
  a[0] * b[1] - a[1] * b[0]];
const unit = (a) => { const l = Math.hypot(...a); return a.map((v) => v / l); };
const rad = (deg) => (deg * Math.PI) / 180;

function cameraDirection(cam) {
  const y = rad(cam.yaw), p = rad(cam.pitch);
  const local = [Math.sin(y) * Math.cos(p), Math.sin(p), Math.cos(y) * Math.cos(p)];
  const b = cam.basis; // columns: the face's left, up, front
  return [0, 1, 2].map((i) => b[i] * local[0] + b[3 + i] * local[1] + b[6 + i] * local[2]);
}

function viewMatrix(cam) {
  const up = cam.basis.slice(3, 6);
  const eye = cameraDirection(cam).map((d, i) => cam.target[i] + cam.distance * d);
  const f = unit(sub(cam.target, eye));
  const s = unit(cross(f, up));
  const u = cross(s, f);
  // column-major, as WebGL takes it
  return new Float32Array([s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
    -dot(s, eye), -dot(u, eye), dot(f, eye), 1]);
}

function projectionMatrix(cam, aspect) {
  const near = Math.max(cam.distance - 2 * cam.radius, cam.distance * 0.01, 1e-4);
  const far = cam.distance + 2 * cam.radius;
  const f = 1 / Math.tan(rad(cam.fov_y) / 2);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
    0, 0, (2 * far * near) / (near - far), 0]);
}

// --- shaders: the studio's files, as GLSL ES 3.00 --------------------------------------------
function shaderSource(files, name, defines) {
  const resolve = (n) => files[n].replace(/^\s*#include\s+"([^"]+)"\s*$/gm, (_, f) => resolve(f));
  const body = resolve(name).replace(/^#version .*$/m, '');
  return ['#version 300 es', 'precision highp float;', 'precision highp int;',
    'precision highp sampler2DArray;', ...defines.map((d) => `#define ${d}`), body].join('\n');
}

function compile(gl, files, defines) {
  const program = gl.createProgram();
  for (const [type, name] of [[gl.VERTEX_SHADER, 'face.vert'], [gl.FRAGMENT_SHADER, 'face.frag']]) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, shaderSource(files, name, defines));
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
      throw new Error(`${name} (${defines.join(' ')}): ${gl.getShaderInfoLog(shader)}`);
    }
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
    throw new Error(`face program: ${gl.getProgramInfoLog(program)}`);
  }
  return program;
}

// --- textures -------------------------------------------------------------------------------
function texture2d(gl, image, mipmaps, aniso) {
  const [h, w] = image.shape;
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, image.data);
  if (mipmaps) gl.generateMipmap(gl.TEXTURE_2D);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER,
    mipmaps ? gl.LINEAR_MIPMAP_LINEAR : gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  if (aniso) gl.texParameterf(gl.TEXTURE_2D, aniso.TEXTURE_MAX_ANISOTROPY_EXT, 8);
  return tex;
}

function textureArray(gl, image, format) {
  const [n, h, w] = image.shape;
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  const [inner, outer] = { rg: [gl.RG8, gl.RG], r: [gl.R8, gl.RED],
    rgba: [gl.RGBA8, gl.RGBA] }[format];
  gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, inner, w, h, n, 0, outer, gl.UNSIGNED_BYTE, image.data);
  gl.generateMipmap(gl.TEXTURE_2D_ARRAY);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return tex;
}

// --- the face on the CPU: poses, normals, tangents, activations ------------------------------
class Face {
  constructor(scene, arrays) {
    this.scene = scene;
    const rest = arrays.rest.data;
    const n = (this.count = arrays.rest.shape[0]);
    this.restPos = new Float32Array(n * 3);
    this.restNrm = new Float32Array(n * 3);
    this.restTan = new Float32Array(n * 4);
    for (let v = 0; v < n; ++v) {
      for (let c = 0; c < 3; ++c) {
        this.restPos[3 * v + c] = rest[10 * v + c];
        this.restNrm[3 * v + c] = rest[10 * v + 3 + c];
      }
      for (let c = 0; c < 4; ++c) this.restTan[4 * v + c] = rest[10 * v + 6 + c];
    }
    this.pos = this.restPos.slice();
    this.nrm = this.restNrm.slice();
    this.tan = this.restTan.slice();
    this.wrinkleRest = this.restPos.slice(); // the rest technique 2 measures from (onsets)
    this.poses = scene.poses.map((pose, k) => ({ step: pose.step, onset: pose.onset || 0,
      vertices: arrays[`pose${k}.vertices`].data, deltas: arrays[`pose${k}.deltas`].data }));
    this.base = arrays['t1.base'].data;
    this.shown = arrays['t1.shown'].data;
    this.areaMaps = arrays['t1.maps'].data;
  }

  // The neutral frame plus each pose's weighted change of position, normal and tangent (the
  // studio's own at each key pose, in steps of pose.step); normals renormalised, tangents made
  // perpendicular again. Technique 2's rest moves by what a pose's onset holds back of it
  // (render/wrinkle_drive.py), so the shader measures the motion past each onset.
  deform(weights) {
    this.pos.set(this.restPos);
    this.nrm.set(this.restNrm);
    this.tan.set(this.restTan);
    this.wrinkleRest.set(this.restPos);
    const { pos, nrm, tan, wrinkleRest } = this;
    this.poses.forEach((pose, k) => {
      const w = weights[k];
      if (!w) return;
      const { vertices, deltas, onset } = pose;
      const [p, n, t] = pose.step.map((s) => s * w);
      const held = onset > 0 ? pose.step[0] * (w - Math.max((w - onset) / (1 - onset), 0)) : 0;
      for (let i = 0; i < vertices.length; ++i) {
        const v = vertices[i], d = 9 * i;
        for (let c = 0; c < 3; ++c) {
          pos[3 * v + c] += p * deltas[d + c];
          nrm[3 * v + c] += n * deltas[d + 3 + c];
          tan[4 * v + c] += t * deltas[d + 6 + c];
          if (held) wrinkleRest[3 * v + c] += held * deltas[d + c];
        }
      }
    });
    for (let v = 0; v < this.count; ++v) {
      const a = 3 * v, b = 4 * v;
      const nl = Math.hypot(nrm[a], nrm[a + 1], nrm[a + 2]);
      if (nl > 0) for (let c = 0; c < 3; ++c) nrm[a + c] /= nl;
      const along = nrm[a] * tan[b] + nrm[a + 1] * tan[b + 1] + nrm[a + 2] * tan[b + 2];
      for (let c = 0; c < 3; ++c) tan[b + c] -= along * nrm[a + c];
      const tl = Math.hypot(tan[b], tan[b + 1], tan[b + 2]);
      if (tl > 1e-6) for (let c = 0; c < 3; ++c) tan[b + c] /= tl;
      else for (let c = 0; c < 3; ++c) tan[b + c] = this.restTan[b + c];
    }
  }

  // Technique 1's activations (activations.js, shared with the three.js module wrinkles.js).
  activations(weights) {
    return wrinkleActivations(this.scene.links, this.base, this.shown, weights);
  }
}

// --- the renderer -----------------------------------------------------------------------------
class Player {
  constructor(gl, scene, files, arrays) {
    this.gl = gl;
    this.scene = scene;
    this.face = new Face(scene, arrays);
    this.camera = { ...scene.camera };
    const maps = `WRINKLE_MAPS ${scene.wrinkle_maps}`;
    const blend = scene.look.blend === 'normal' ? ['BLEND_NORMALS'] : [];
    // the skin look (skin.glsl) under the studio's rig, with each wrinkled map's cavity and
    // colour where the face has them; clay otherwise
    if (scene.look.rig) blend.push('SKIN', ...(scene.look.tone ? ['SKIN_TONE'] : []));
    this.programs = {
      none: compile(gl, files, ['TECHNIQUE_NONE', ...blend, maps]),
      t1: compile(gl, files, ['TECHNIQUE_T1', 'T1_DIRECT', ...blend, maps]),
      t2: compile(gl, files, ['TECHNIQUE_T2', ...blend, maps]),
    };
    const aniso = gl.getExtension('EXT_texture_filter_anisotropic');
    this.textures = [
      [UNIT.diffuse, gl.TEXTURE_2D, texture2d(gl, arrays.diffuse, true, aniso)],
      [UNIT.normals, gl.TEXTURE_2D, texture2d(gl, arrays.normals, true, aniso)],
      [UNIT.more_maps, gl.TEXTURE_2D_ARRAY, textureArray(gl, arrays.more_maps, 'rg')],
      [UNIT.masks, gl.TEXTURE_2D_ARRAY, textureArray(gl, arrays.masks, 'r')],
    ];
    if (arrays.tone) {
      this.textures.push([UNIT.tone, gl.TEXTURE_2D_ARRAY, textureArray(gl, arrays.tone, 'rgba')]);
    }
    this.activationTexture = gl.createTexture();
    this.textures.push([UNIT.activations, gl.TEXTURE_2D, this.activationTexture]);
    this.buildBuffers(arrays);
  }

  buildBuffers(arrays) {
    const gl = this.gl, face = this.face;
    const make = (data, usage = gl.STATIC_DRAW) => {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, usage);
      return b;
    };
    this.dynamic = {
      in_position: [make(face.pos, gl.DYNAMIC_DRAW), 3, face.pos],
      in_normal: [make(face.nrm, gl.DYNAMIC_DRAW), 3, face.nrm],
      in_tangent: [make(face.tan, gl.DYNAMIC_DRAW), 4, face.tan],
      in_rest: [make(face.wrinkleRest, gl.DYNAMIC_DRAW), 3, face.wrinkleRest],
    };
    const attributes = {
      ...Object.fromEntries(Object.entries(this.dynamic).map(([k, [b, size]]) => [k, [b, size]])),
      in_uv: [make(arrays.uvs.data), 2],
      in_skin: [make(arrays.skin.data), 1],
      in_wdv: [make(arrays['wdv.dirs'].data), 16],
      in_cone: [make(arrays['wdv.cones'].data), 4],
      in_slot_map: [make(arrays['wdv.maps'].data), 4],
    };
    const indices = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, arrays.triangles.data, gl.STATIC_DRAW);
    this.indexCount = arrays.triangles.data.length;
    this.vaos = {};
    for (const [key, program] of Object.entries(this.programs)) {
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      for (const [name, [buffer, size]] of Object.entries(attributes)) {
        const at = gl.getAttribLocation(program, name);
        if (at < 0) continue; // not used by this technique
        gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
        for (let col = 0; col < Math.ceil(size / 4); ++col) { // a mat4 takes four locations
          gl.enableVertexAttribArray(at + col);
          gl.vertexAttribPointer(at + col, Math.min(size, 4), gl.FLOAT, false, size * 4,
            col * 16);
        }
      }
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indices);
      this.vaos[key] = vao;
    }
    gl.bindVertexArray(null);
  }

  setPose(weights) {
    const gl = this.gl, face = this.face;
    face.deform(weights);
    for (const [buffer, , data] of Object.values(this.dynamic)) {
      gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
      gl.bufferSubData(gl.ARRAY_BUFFER, 0, data);
    }
    const values = face.activations(weights);
    const n = Math.max(values.length, 1);
    const texels = new Float32Array(2 * n);
    values.forEach((a, i) => { texels[2 * i] = a; texels[2 * i + 1] = face.areaMaps[i]; });
    gl.bindTexture(gl.TEXTURE_2D, this.activationTexture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RG32F, n, 1, 0, gl.RG, gl.FLOAT, texels);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  }

  draw(technique) {
    const gl = this.gl, canvas = gl.canvas, look = this.scene.look;
    const width = Math.round(canvas.clientWidth * devicePixelRatio);
    const height = Math.round(canvas.clientHeight * devicePixelRatio);
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    gl.viewport(0, 0, width, height);
    gl.clearColor(...look.background, 1);
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.CULL_FACE);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const program = this.programs[technique];
    gl.useProgram(program);
    const set = (name, fn, ...value) => {
      const at = gl.getUniformLocation(program, name);
      if (at !== null) fn.call(gl, at, ...value);
    };
    set('u_view', gl.uniformMatrix4fv, false, viewMatrix(this.camera));
    set('u_proj', gl.uniformMatrix4fv, false, projectionMatrix(this.camera, width / height));
    set('u_light_dir', gl.uniform3fv, unit(look.light_dir));
    set('u_ambient', gl.uniform1f, look.ambient);
    set('u_specular', gl.uniform1f, look.specular);
    set('u_shininess', gl.uniform1f, look.shininess);
    if (look.rig) {
      set('u_rig_dir', gl.uniform3fv, look.rig.directions.flat());
      set('u_rig_colour', gl.uniform3fv, look.rig.colours.flat());
      set('u_rig_ambient', gl.uniform3fv, look.rig.ambient);
    }
    set('u_view_mode', gl.uniform1i, 0);
    set('u_expression', gl.uniform1f, this.scene.wdv.expression_factor);
    set('u_scale_free', gl.uniform1i, this.scene.wdv.scale_free ? 1 : 0);
    for (const [name, unitIndex] of Object.entries(UNIT)) {
      set(`u_${name}`, gl.uniform1i, unitIndex);
    }
    for (const [unitIndex, target, tex] of this.textures) {
      gl.activeTexture(gl.TEXTURE0 + unitIndex);
      gl.bindTexture(target, tex);
    }
    gl.bindVertexArray(this.vaos[technique]);
    gl.drawElements(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
  }
}

// --- the timeline -----------------------------------------------------------------------------
function timelineWeights(timeline, frame, out) {
  const frames = timeline.frames;
  let hi = frames.findIndex((f) => f >= frame);
  if (hi < 0) hi = frames.length - 1;
  const lo = Math.max(hi - 1, 0);
  const span = frames[hi] - frames[lo];
  const f = span > 0 ? Math.min(Math.max((frame - frames[lo]) / span, 0), 1) : 1;
  for (let k = 0; k < out.length; ++k) {
    out[k] = timeline.weights[lo][k] * (1 - f) + timeline.weights[hi][k] * f;
  }
}

// --- the page ---------------------------------------------------------------------------------
async function main() {
  const scene = JSON.parse(document.getElementById('scene').textContent);
  const files = JSON.parse(document.getElementById('shaders').textContent);
  const query = readQuery(scene);
  if (query.bare) document.body.classList.add('bare');
  const canvas = document.getElementById('view');
  const gl = canvas.getContext('webgl2', { antialias: true });
  if (!gl) throw new Error('this browser offers no WebGL2');
  const arrays = readArrays(await inflate(document.getElementById('data').textContent),
    scene.arrays);
  const player = new Player(gl, scene, files, arrays);
  const state = { technique: query.technique, weights: query.weights, playing: false, frame: 0 };
  let pending = false;
  const redraw = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; player.draw(state.technique); });
  };

  // the panel: technique, timeline, one slider per key pose
  const techniques = document.getElementById('techniques');
  for (const [key, label] of Object.entries(TECHNIQUES)) {
    const row = document.createElement('label');
    const input = Object.assign(document.createElement('input'),
      { type: 'radio', name: 'technique', value: key, checked: key === state.technique });
    input.addEventListener('change', () => { state.technique = key; redraw(); });
    row.append(input, label);
    techniques.append(row);
  }
  const sliders = scene.poses.map((pose, k) => {
    const row = document.createElement('div');
    row.className = 'pose';
    const name = Object.assign(document.createElement('span'), { textContent: pose.name,
      title: pose.name });
    const input = Object.assign(document.createElement('input'),
      { type: 'range', min: 0, max: 1, step: 0.01, value: state.weights[k] });
    const value = Object.assign(document.createElement('span'),
      { textContent: state.weights[k].toFixed(2) });
    input.addEventListener('input', () => {
      stop();
      state.weights[k] = Number(input.value);
      value.textContent = state.weights[k].toFixed(2);
      player.setPose(state.weights);
      redraw();
    });
    row.append(name, input, value);
    document.getElementById('poses').append(row);
    return [input, value];
  });
  const showWeights = () => sliders.forEach(([input, value], k) => {
    input.value = state.weights[k];
    value.textContent = state.weights[k].toFixed(2);
  });

  const timeline = scene.timeline;
  const play = document.getElementById('play');
  const scrub = document.getElementById('frame');
  let started = 0, from = 0;
  function stop() {
    state.playing = false;
    play.textContent = 'Play';
  }
  function showFrame(frame) {
    state.frame = frame;
    scrub.value = frame;
    timelineWeights(timeline, frame, state.weights);
    showWeights();
    player.setPose(state.weights);
    player.draw(state.technique);
  }
  function playFrom(frame, at) {
    // the timeline at ``frame`` at page time ``at`` (ms), playing on from there
    state.playing = true;
    play.textContent = 'Pause';
    started = at;
    from = frame;
    requestAnimationFrame(tick);
  }
  function tick(now) {
    if (!state.playing) return;
    const first = timeline.frames[0], last = timeline.frames[timeline.frames.length - 1];
    const length = Math.max(last - first, 1e-9);
    showFrame(first + ((from - first + ((now - started) / 1000) * timeline.fps) % length));
    requestAnimationFrame(tick);
  }
  if (timeline) {
    scrub.min = timeline.frames[0];
    scrub.max = timeline.frames[timeline.frames.length - 1];
    play.addEventListener('click', () => {
      if (state.playing) stop(); else playFrom(state.frame, performance.now());
    });
    scrub.addEventListener('input', () => { stop(); showFrame(Number(scrub.value)); });
  } else {
    document.getElementById('timeline').hidden = true;
  }

  // orbit by dragging, zoom with the wheel (the studio's limits)
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    drag = [e.clientX, e.clientY];
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const cam = player.camera;
    cam.yaw = (cam.yaw - (e.clientX - drag[0]) * 0.4) % 360;
    cam.pitch = Math.min(Math.max(cam.pitch + (e.clientY - drag[1]) * 0.4, -89), 89);
    drag = [e.clientX, e.clientY];
    redraw();
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const cam = player.camera;
    cam.distance = Math.min(Math.max(cam.distance * Math.exp(e.deltaY * 0.001),
      cam.radius * 0.05), cam.radius * 100);
    redraw();
  }, { passive: false });
  addEventListener('resize', redraw);

  player.setPose(state.weights);
  player.draw(state.technique);
  if (query.problems.length) say(query.problems.join('; '));
  // no pose asked for: the timeline plays, from its first frame when the page opened (not
  // when its data was inflated: how long that takes varies, the frame shown at a moment not)
  if (timeline && !query.still) playFrom(timeline.frames[0], 0);
  document.body.dataset.ready = 'true';
}

main().catch((error) => {
  say(`The player cannot start: ${error.message}`);
  document.body.dataset.ready = 'error';
});
