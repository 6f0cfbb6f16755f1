// Runs an exported web page's own script under node (no browser, no WebGL): the page's data is
// inflated by its own code, and its `Face` turns each given set of pose weights into technique
// 1's activations exactly as the page does before drawing.
//
//   node page_activations.cjs PAGE.html < weights.json   (a list of lists, one weight per pose)
//   node page_activations.cjs PAGE.html rest < weights.json
//
// Prints a JSON list of activation lists (with `rest`: of the rest positions technique 2
// measures from, x y z per vertex, after the page's own `deform`). The page's `main` is left to fail on the missing
// canvas (the stand-in document has none); everything it declares stays in the context.
'use strict';
const fs = require('fs');
const vm = require('vm');

const page = fs.readFileSync(process.argv[2], 'utf8');
const element = (id) => {
  const found = page.match(new RegExp(`<script[^>]*id="${id}">([\\s\\S]*?)</script>`));
  if (!found) throw new Error(`the page has no ${id} element`);
  return found[1];
};
const script = page.match(/<script>\n([\s\S]*?)<\/script>\s*<\/body>/)[1];
const quiet = { textContent: '', dataset: {}, classList: { add() {} } };
const document = { getElementById: () => quiet, body: quiet };
const context = vm.createContext({ document, atob, Blob, Response, DecompressionStream,
  location: { search: '' }, console });
vm.runInContext(script, context, { filename: 'page-script.js' });
context.sceneText = element('scene');
context.dataText = element('data');
context.weightSets = JSON.parse(fs.readFileSync(0, 'utf8'));
context.wanted = process.argv[3] === 'rest' ? 'rest' : 'activations';
const run = `(async () => {
  const scene = JSON.parse(sceneText);
  const face = new Face(scene, readArrays(await inflate(dataText), scene.arrays));
  const of = (w) => {
    if (wanted === 'activations') return Array.from(face.activations(w));
    face.deform(w);
    return Array.from(face.wrinkleRest);
  };
  return JSON.stringify(weightSets.map((w) => of(Float32Array.from(w))));
})()`;
vm.runInContext(run, context).then((text) => process.stdout.write(text));
