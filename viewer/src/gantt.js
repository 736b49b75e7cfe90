// The step's timeline: one row per thread, a bar per piece of work (weight-driven stage, depth-first
// traversal of a run-time task or pair, finalization of a pair), coloured by thread as the task
// boxes are; stage and finalization drawn lighter.

import { threadColour } from './geometry.js';

const phases = ['stage', 'traverse', 'finalize'];

export function drawGantt(canvas, step, threads) {
  const ratio = window.devicePixelRatio || 1;
  canvas.width = Math.round(canvas.clientWidth * ratio);
  canvas.height = Math.round(canvas.clientHeight * ratio);
  const g = canvas.getContext('2d');
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  g.clearRect(0, 0, w, h);
  const spans = step.timeline;  // [thread, start_ms, end_ms, phase, unit]
  const end = spans.reduce((m, s) => Math.max(m, s[2]), 0);
  const left = 70;
  const row = (h - 18) / Math.max(threads, 1);
  g.font = '11px sans-serif';
  g.fillStyle = '#333';
  for (let t = 0; t < threads; ++t) g.fillText(`thread ${t}`, 4, 12 + row * t + row / 2);
  g.fillText(`0 … ${end.toFixed(2)} ms (narrow phase)`, left, h - 4);
  if (end <= 0) return;
  const x = (ms) => left + ((w - left - 8) * ms) / end;
  for (const [thread, start, stop, phase] of spans) {
    const colour = threadColour(thread, threads);
    g.globalAlpha = phases[phase] === 'traverse' ? 1 : 0.4;
    g.fillStyle = '#' + colour.getHexString();
    g.fillRect(x(start), 4 + row * thread, Math.max(x(stop) - x(start), 1), row - 4);
  }
  g.globalAlpha = 1;
}
