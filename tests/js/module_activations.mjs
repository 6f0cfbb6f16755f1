// Runs the exported wrinkles.js under node (no browser): its own per-frame path from a mesh's
// morphTargetInfluences to technique 1's activations, on the player data of the exported .glb.
//
//   node module_activations.mjs FOLDER < weights.json   (a list of lists, one weight per pose)
//
// FOLDER holds face.glb and wrinkles.js, and node_modules/three. Prints a JSON list of
// activation lists.
import fs from 'fs';
import path from 'path';
import { pathToFileURL } from 'url';

const folder = process.argv[2];
const { activationsOf } = await import(pathToFileURL(path.join(folder, 'wrinkles.js')).href);
const glb = fs.readFileSync(path.join(folder, 'face.glb'));
const jsonLength = glb.readUInt32LE(12);
const json = JSON.parse(glb.subarray(20, 20 + jsonLength).toString('utf8'));
const bin = glb.subarray(20 + jsonLength + 8);
const player = json.extras.wrinklePlayer;
const arrays = {};
for (const [name, spec] of Object.entries(player.arrays)) {
  const view = json.bufferViews[spec.bufferView];
  const bytes = bin.subarray(view.byteOffset || 0, (view.byteOffset || 0) + view.byteLength);
  arrays[name] = { data: new Float32Array(Uint8Array.from(bytes).buffer), shape: spec.shape };
}
// the mesh as GLTFLoader makes it: morph targets by name, in the file's target order
const names = json.meshes[0].extras.targetNames;
const mesh = { morphTargetDictionary: Object.fromEntries(names.map((n, k) => [n, k])),
  morphTargetInfluences: names.map(() => 0) };
const weightSets = JSON.parse(fs.readFileSync(0, 'utf8'));
process.stdout.write(JSON.stringify(weightSets.map((weights) => {
  weights.forEach((w, k) => { mesh.morphTargetInfluences[k] = w; });
  return Array.from(activationsOf(player, arrays, mesh));
})));
