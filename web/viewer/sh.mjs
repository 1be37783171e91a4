// E(n) of radiance SH coefficients as daylit serves them (docs/serve.md: 27 numbers, coefficient-
// major, Â_l folded in here as three.js's shGetIrradianceAt does). Used by the viewer (the shadow
// catcher) and by its test (the shading it expects three.js to draw).
export function shIrradiance(c, n) {
  const [x, y, z] = n;
  const w = [0.886227, 1.023328 * y, 1.023328 * z, 1.023328 * x, 0.858086 * x * y, 0.858086 * y * z,
             0.743125 * z * z - 0.247708, 0.858086 * x * z, 0.429043 * (x * x - y * y)];
  const e = [0, 0, 0];
  for (let k = 0; k < 9; ++k) for (let ch = 0; ch < 3; ++ch) e[ch] += w[k] * c[3 * k + ch];
  return e;
}
