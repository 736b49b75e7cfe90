// Decoding the recorded meshes and the viewer's colours.

import * as THREE from 'three';

function bytes(base64) {
  const text = atob(base64);
  const out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) out[i] = text.charCodeAt(i);
  return out.buffer;
}

/// One BufferGeometry per recorded mesh: vertices (float32, little-endian, object frame) and
/// triangles (uint32), both base64.
export function decodeMeshes(meshes) {
  return meshes.map((m) => {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(bytes(m.vertices)), 3));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(m.triangles)), 1));
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    return geometry;
  });
}

/// A share in [0, 1] as a colour from blue (no work) through yellow to red (all of the step's work).
export function heat(share) {
  const s = Math.min(Math.max(share, 0), 1);
  return new THREE.Color().setHSL((1 - Math.sqrt(s)) * 0.66, 0.9, 0.5);
}

/// A distinct colour per worker thread.
export function threadColour(thread, threads) {
  return new THREE.Color().setHSL(((thread * 0.61803) % 1 + 1) % 1, 0.8, threads > 1 ? 0.45 : 0.35);
}

/// Appends the 12 edges (24 points) of a box with centre c and half-extents h, in the object frame
/// that `matrix` poses.
export function boxEdges(out, matrix, cx, cy, cz, hx, hy, hz) {
  const corner = (i) =>
    new THREE.Vector3(cx + (i & 1 ? hx : -hx), cy + (i & 2 ? hy : -hy), cz + (i & 4 ? hz : -hz)).applyMatrix4(matrix);
  const corners = Array.from({ length: 8 }, (_, i) => corner(i));
  const edges = [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]];
  for (const [a, b] of edges) out.push(corners[a].x, corners[a].y, corners[a].z, corners[b].x, corners[b].y, corners[b].z);
}
