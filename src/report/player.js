// catflip report player: both halves of the cat, for each method's simulated
// motion, drawn on a 2-D canvas as flat-shaded polygons in painter's order.
// No libraries, no network: the frames are the JSON in <script id="scene">.
(function () {
  'use strict';
  const scene = JSON.parse(document.getElementById('scene').textContent);
  const halves = { A: scene.rear, B: scene.front };
  const L = (scene.rear.length + scene.front.length) / 2; // sets the view's scale
  const tracks = scene.tracks;
  const tEnd = Math.max(...tracks.map(tr => tr.frames[tr.frames.length - 1].t));
  const COLORS = { A: [214, 120, 40], B: [60, 110, 190] };
  const view0 = { yaw: 0.55, pitch: 0.3 };
  const state = { t: 0, playing: false, speed: 0.25, yaw: view0.yaw, pitch: view0.pitch };

  // --- quaternions [w, x, y, z] -------------------------------------------
  function rot(q, v) {
    const [w, x, y, z] = q;
    const tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
    return [v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz, v[2] + w * tz + x * ty - y * tx];
  }
  function nlerp(a, b, s) {
    const sign = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0 ? -1 : 1;
    const q = a.map((v, i) => v + s * (sign * b[i] - v));
    const n = Math.hypot(...q);
    return q.map(v => v / n);
  }
  const add = (u, v) => [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
  const scale = (u, k) => [u[0] * k, u[1] * k, u[2] * k];

  // The state of one method at time t, interpolated between its frames.
  function sample(track, t) {
    const f = track.frames;
    let lo = 0, hi = f.length - 1;
    if (t <= f[0].t) hi = 0;
    else if (t >= f[hi].t) lo = hi;
    else while (hi - lo > 1) { const m = (lo + hi) >> 1; if (f[m].t <= t) lo = m; else hi = m; }
    const s = hi === lo ? 0 : (t - f[lo].t) / (f[hi].t - f[lo].t);
    const mix = k => f[lo][k] + s * (f[hi][k] - f[lo][k]);
    return { a: nlerp(f[lo].a, f[hi].a, s), b: nlerp(f[lo].b, f[hi].b, s),
      flip: mix('flip_deg'), bend: mix('bend_deg'), tau: mix('tau_nm') };
  }

  // --- geometry: a cylinder along body z, centred on its centre of mass ----
  const SEG = 28;
  function cylinder(q, centre, body) {
    const faces = [], ring = [], R = halves[body].radius, L = halves[body].length;
    const at = (x, y, z) => add(centre, rot(q, [x, y, z]));
    for (let i = 0; i < SEG; i++) {
      const a = 2 * Math.PI * (i + 0.5) / SEG;
      ring.push([R * Math.cos(a), R * Math.sin(a)]);
    }
    for (let i = 0; i < SEG; i++) {
      const [x0, y0] = ring[i], [x1, y1] = ring[(i + 1) % SEG];
      const mid = 2 * Math.PI * (i + 1) / SEG;
      const n = [Math.cos(mid), Math.sin(mid), 0];
      // the back (body -x) is darker, so the roll shows on the body itself
      faces.push({ pts: [at(x0, y0, -L / 2), at(x1, y1, -L / 2), at(x1, y1, L / 2), at(x0, y0, L / 2)],
        n: rot(q, n), body, dark: n[0] < -0.6 });
    }
    for (const end of [-1, 1])
      faces.push({ pts: ring.map(([x, y]) => at(x, y, end * L / 2)), n: rot(q, [0, 0, end]), body });
    // two belly stubs (legs) on body +x
    const legs = [-0.3, 0.3].map(z => [at(R, 0, z * L), at(R + 0.45 * L, 0, z * L)]);
    return { faces, legs };
  }

  // --- a general half: its inertia-equivalent box about its centre of mass ---
  function qmul(p, q) {
    const [a, b, c, d] = p, [e, f, g, h] = q;
    return [a * e - b * f - c * g - d * h, a * f + b * e + c * h - d * g,
      a * g - b * h + c * e + d * f, a * h + b * g - c * f + d * e];
  }
  function box(q, centre, body) {
    const bx = scene.boxes[body === 'A' ? 0 : 1], e = bx.edges.map(v => v / 2), qb = qmul(q, bx.quat);
    const at = (x, y, z) => add(centre, rot(qb, [x * e[0], y * e[1], z * e[2]]));
    const faces = [];
    for (let k = 0; k < 3; k++) for (const sgn of [-1, 1]) {
      const u = (k + 1) % 3, v = (k + 2) % 3, corner = (a, b) => { const p = [0, 0, 0]; p[k] = sgn; p[u] = a; p[v] = b; return at(...p); };
      const n = [0, 0, 0]; n[k] = sgn;
      const nw = rot(qb, n), belly = rot(q, [1, 0, 0]);
      const back = nw[0] * belly[0] + nw[1] * belly[1] + nw[2] * belly[2];
      faces.push({ pts: [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)], n: nw, body,
        dark: back < -0.6 });
    }
    // two belly stubs on the half's +x, from the box's surface
    const reach = [0, 1, 2].reduce((acc, k) => { const ax = [0, 0, 0]; ax[k] = 1; return acc + Math.abs(rot(bx.quat, ax)[0]) * e[k]; }, 0);
    const legs = [-0.3, 0.3].map(z => [add(centre, rot(q, [reach, 0, z * L])), add(centre, rot(q, [reach + 0.45 * L, 0, z * L]))]);
    return { faces, legs };
  }

  // Both halves, placed so that the common centre of mass stays at the origin:
  // d runs from A's centre through the joint to B's centre.
  function pose(s) {
    const { A, B } = halves, m = A.mass + B.mass;
    if (scene.boxes) {
      const d = add(rot(s.a, scene.boxes[0].to_joint), rot(s.b, scale(scene.boxes[1].to_joint, -1)));
      return [box(s.a, scale(d, -B.mass / m), 'A'), box(s.b, scale(d, A.mass / m), 'B')];
    }
    const d = add(rot(s.a, [0, 0, A.length / 2]), rot(s.b, [0, 0, B.length / 2]));
    return [cylinder(s.a, scale(d, -B.mass / m), 'A'), cylinder(s.b, scale(d, A.mass / m), 'B')];
  }

  // --- camera: world x is up on screen at rest, the spine (z) runs right ---
  function camera(p) {
    const X = p[2], Y = p[0], Z = p[1];
    const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), cp = Math.cos(state.pitch), sp = Math.sin(state.pitch);
    const x1 = X * cy + Z * sy, z1 = -X * sy + Z * cy;
    return [x1, Y * cp - z1 * sp, Y * sp + z1 * cp];
  }

  function render(view, t) {
    const { canvas, ctx } = view;
    const W = canvas.width, H = canvas.height, dist = 8 * L, f = 0.36 * W / L * dist;
    const proj = p => { const c = camera(p); const k = f / (dist - c[2]); return [W / 2 + c[0] * k, H / 2 - c[1] * k, c[2]]; };
    const s = sample(view.track, t);
    const bodies = pose(s);
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, W, H);
    // the initial spine, dashed, and the direction of gravity (world -x)
    ctx.setLineDash([6, 5]); ctx.strokeStyle = '#999'; ctx.lineWidth = 1;
    const s0 = proj([0, 0, -1.6 * L]), s1 = proj([0, 0, 1.6 * L]);
    ctx.beginPath(); ctx.moveTo(s0[0], s0[1]); ctx.lineTo(s1[0], s1[1]); ctx.stroke();
    ctx.setLineDash([]);
    // gravity (world -x) as an arrow from a fixed corner, turning with the camera
    const g = camera([-1, 0, 0]), gl = Math.hypot(g[0], g[1]) || 1;
    const g0 = [40, 40], g1 = [40 + 28 * g[0] / gl, 40 - 28 * g[1] / gl];
    arrow(ctx, g0, g1); ctx.fillStyle = '#555'; ctx.font = '12px sans-serif'; ctx.fillText('down', 8, 16);
    const light = [-0.4, 0.6, 0.7];
    const items = [];
    for (const b of bodies) {
      for (const fc of b.faces) {
        const n = camera(fc.n);
        if (n[2] <= 0) continue;
        const pts = fc.pts.map(proj);
        const depth = pts.reduce((acc, p) => acc + p[2], 0) / pts.length;
        const lum = 0.35 + 0.65 * Math.max(0, n[0] * light[0] + n[1] * light[1] + n[2] * light[2]);
        const c = COLORS[fc.body].map(v => Math.round(v * lum * (fc.dark ? 0.55 : 1)));
        items.push({ depth, draw: () => polygon(ctx, pts, `rgb(${c})`) });
      }
      for (const [p, q] of b.legs) {
        const a = proj(p), e = proj(q);
        items.push({ depth: (a[2] + e[2]) / 2, draw: () => segment(ctx, a, e) });
      }
    }
    items.sort((u, v) => u.depth - v.depth).forEach(it => it.draw());
    view.drawnLegs = bodies.flatMap(b => b.legs.map(([, q]) => proj(q).slice(0, 2)));
    const lim = scene.max_torque_nm;
    const over = lim != null && s.tau >= lim * (1 - 1e-6); // the simulation clips at the limit
    // past a track's touchdown (a shorter drop's) its last torque is not held
    const end = view.track.frames[view.track.frames.length - 1].t;
    const torque = t > end + 1e-9
      ? `landed at t = ${end.toFixed(3)} s`
      : `torque ${s.tau.toPrecision(4)} N m (${scene.norm})` + (lim != null ? ` / limit ${lim}` : '') + (over ? ' <b>at the limit</b>' : '');
    view.readout.innerHTML = `t = ${t.toFixed(3)} s<br>flip ${s.flip.toFixed(1)} deg<br>bend ${s.bend.toFixed(1)} deg<br>` + torque;
    return s;
  }

  // A face, filled and outlined in its own colour (no seams between faces).
  function polygon(ctx, pts, color) {
    ctx.fillStyle = ctx.strokeStyle = color;
    ctx.lineWidth = 1;
    ctx.beginPath();
    pts.forEach((p, i) => (i ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1])));
    ctx.closePath();
    ctx.fill();
    ctx.stroke();
  }

  // A belly stub.
  function segment(ctx, a, e) {
    ctx.strokeStyle = '#222';
    ctx.lineWidth = 4;
    ctx.lineCap = 'round';
    ctx.beginPath();
    ctx.moveTo(a[0], a[1]);
    ctx.lineTo(e[0], e[1]);
    ctx.stroke();
  }

  function arrow(ctx, a, b) {
    ctx.strokeStyle = '#555'; ctx.lineWidth = 1.5; ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]);
    const ang = Math.atan2(b[1] - a[1], b[0] - a[0]);
    for (const s of [-1, 1]) { ctx.moveTo(b[0], b[1]); ctx.lineTo(b[0] - 8 * Math.cos(ang + s * 0.4), b[1] - 8 * Math.sin(ang + s * 0.4)); }
    ctx.stroke();
  }

  // --- page: one view per method, shared clock and camera -----------------
  const views = tracks.map(track => {
    const div = document.createElement('div');
    div.className = 'view';
    div.innerHTML = `<h3>${track.name}</h3><div class="status">${track.status}</div>`;
    const canvas = document.createElement('canvas');
    canvas.width = 320; canvas.height = 300;
    const readout = document.createElement('div');
    readout.className = 'readout';
    div.append(canvas, readout);
    document.getElementById('views').append(div);
    return { track, canvas, ctx: canvas.getContext('2d'), readout };
  });
  const slider = document.getElementById('time'), clock = document.getElementById('clock');
  const playButton = document.getElementById('play');
  function draw() {
    views.forEach(v => render(v, state.t));
    slider.value = Math.round(1000 * state.t / tEnd);
    clock.textContent = `t = ${state.t.toFixed(3)} s of ${tEnd.toFixed(3)} s`;
  }
  function setTime(t) { state.t = Math.min(Math.max(t, 0), tEnd); draw(); }
  let last = null;
  function tick(now) {
    if (!state.playing) return;
    if (last !== null) state.t += state.speed * (now - last) / 1000;
    last = now;
    if (state.t >= tEnd) { state.t = tEnd; state.playing = false; playButton.textContent = 'play'; }
    draw();
    if (state.playing) requestAnimationFrame(tick);
  }
  function play(on) {
    state.playing = on;
    playButton.textContent = on ? 'pause' : 'play';
    if (on) { if (state.t >= tEnd) state.t = 0; last = null; requestAnimationFrame(tick); }
  }
  playButton.addEventListener('click', () => play(!state.playing));
  slider.addEventListener('input', () => { play(false); setTime(slider.value / 1000 * tEnd); });
  document.getElementById('speed').addEventListener('change', e => { state.speed = +e.target.value; });
  document.getElementById('reset-view').addEventListener('click', () => { state.yaw = view0.yaw; state.pitch = view0.pitch; draw(); });
  let drag = null;
  for (const v of views) {
    v.canvas.addEventListener('pointerdown', e => { drag = [e.clientX, e.clientY]; v.canvas.setPointerCapture(e.pointerId); });
    v.canvas.addEventListener('pointermove', e => {
      if (!drag) return;
      state.yaw += 0.01 * (e.clientX - drag[0]);
      state.pitch = Math.max(-1.5, Math.min(1.5, state.pitch + 0.01 * (e.clientY - drag[1])));
      drag = [e.clientX, e.clientY];
      draw();
    });
    v.canvas.addEventListener('pointerup', () => { drag = null; });
  }
  // #t=0.7 opens the page at that instant (for links and screenshots)
  const at = /t=([0-9.]+)/.exec(location.hash);
  setTime(at ? +at[1] : 0);

  // --- #selftest: render two instants, play briefly, report into the DOM ---
  if (location.hash === '#selftest') {
    const out = { tracks: tracks.length, frames: tracks.map(tr => tr.frames.length), t_end: tEnd };
    const legs = () => views.map(v => v.drawnLegs);
    setTime(0); const start = legs();
    setTime(tEnd / 2); const mid = legs();
    setTime(tEnd);
    // each view's readout at the end, and its track's own last instant
    out.readout_end = views.map(v => v.readout.textContent);
    out.track_end_s = tracks.map(tr => tr.frames[tr.frames.length - 1].t);
    // largest on-screen move of a belly stub between the two instants, px
    out.leg_move_px = views.map((v, i) => Math.max(...mid[i].map((p, k) => Math.hypot(p[0] - start[i][k][0], p[1] - start[i][k][1]))));
    // world x of body A's belly at the end: cos(flip) for a straight, untilted cat
    out.belly_x_end = tracks.map(tr => rot(tr.frames[tr.frames.length - 1].a, [1, 0, 0])[0]);
    out.flip_end_deg = tracks.map(tr => tr.frames[tr.frames.length - 1].flip_deg);
    // the page's layout: what overflows the window sideways, px
    out.window_width_px = window.innerWidth;
    out.page_width_px = document.documentElement.scrollWidth;
    out.table_right_px = document.querySelector('table').getBoundingClientRect().right;
    const wide = document.querySelector('.wide');
    out.table_scrolls = !!wide && wide.scrollWidth > wide.clientWidth;
    setTime(0);
    play(true);
    // the clock moves from the second animation frame on: wait for it, at
    // most 60 s of the page's time (a headless browser's virtual time runs
    // ahead of the frames a loaded machine draws: one frame in 4 s was seen)
    const started = performance.now();
    const report = () => {
      if (state.t === 0 && performance.now() - started < 60000) { setTimeout(report, 100); return; }
      out.played_to_s = state.t;
      play(false);
      out.errors = window.catflipErrors || [];
      const pre = document.getElementById('selftest');
      pre.textContent = JSON.stringify(out);
      pre.hidden = false;
    };
    setTimeout(report, 100);
  }
})();
