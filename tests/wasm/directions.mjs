// SPDX-License-Identifier: MIT
// Fixed directions for the node tests and the wasm benchmark: hemisphere(seed) returns a function
// that gives n directions (Float64Array, xyz per direction) uniform on the upper hemisphere (z
// uniform in [0, 1), phi uniform), each call continuing one Park-Miller sequence from `seed`.
export function hemisphere(seed) {
  const rand = () => (seed = (seed * 16807) % 2147483647) / 2147483647;
  return (n) => {
    const d = new Float64Array(3 * n);
    for (let k = 0; k < n; ++k) {
      const z = rand(), phi = 2 * Math.PI * rand(), r = Math.sqrt(1 - z * z);
      d[3 * k] = r * Math.cos(phi);
      d[3 * k + 1] = r * Math.sin(phi);
      d[3 * k + 2] = z;
    }
    return d;
  };
}
