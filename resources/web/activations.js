// Technique 1's activations from pose weights: each area's own value plus gain * curve(weight)
// of its links, clamped to [0, 1] (core/wrinkles/influence.py), the weight first through its
// pose's onset (core/wrinkles/response.py onset_weight); hidden areas show nothing.
// One source for both players: the exported web page (player.js) and the three.js module
// (wrinkles.js), each given the links as core/formats/player_data.py writes them: {pose, area,
// gain, curve, onset}, the curve sampled evenly on [0, 1] and read linearly in between.
function wrinkleActivations(links, base, shown, weights) {
  const out = Float32Array.from(base);
  for (const link of links) {
    const w = Math.min(Math.max(weights[link.pose] || 0, 0), 1);
    const onset = link.onset || 0;
    const x = (onset > 0 ? Math.max((w - onset) / (1 - onset), 0) : w) * (link.curve.length - 1);
    const i = Math.min(Math.floor(x), link.curve.length - 2), f = x - i;
    out[link.area] += link.gain * (link.curve[i] * (1 - f) + link.curve[i + 1] * f);
  }
  return out.map((a, i) => (shown[i] ? Math.min(Math.max(a, 0), 1) : 0));
}
