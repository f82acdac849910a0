// lipsync edit: the page. Everything it knows about phonemes, poses and the mouth comes from
// GET /api/bigrams; curves are validated and smoothed by the server (the same code `lipsync
// animate` runs), so what is drawn here is what the runtime plays.
'use strict';

const SVG = 'http://www.w3.org/2000/svg';
const token = new URLSearchParams(location.search).get('token') || '';
const app = {
  info: null,          // GET /api/bigrams
  pair: null,          // "f-ah"
  bigram: null,        // GET /api/bigrams/f/ah
  undo: [], redo: [],  // {pair, poses} snapshots
  selected: null,      // {pose, index}
  drag: null,          // {pose, index, before, svg}
  preview: null,       // POST /api/preview
  used: new Set(),
  sending: false, pending: false,
};
const $ = (id) => document.getElementById(id);
const clamp = (x, lo, hi) => Math.min(hi, Math.max(lo, x));
const round3 = (x) => Math.round(x * 1000) / 1000;

async function api(method, path, body) {
  const res = await fetch(path, {
    method,
    headers: { 'X-Lipsync-Token': token, 'Content-Type': 'application/json' },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  const data = await res.json().catch(() => ({ error: res.status + ' ' + res.statusText }));
  if (!res.ok) throw new Error(data.error || res.statusText);
  return data;
}

function showError(e) { $('error').textContent = e ? String(e.message || e) : ''; }
function setStatus(text) { $('status').textContent = text; }
function el(name, attrs, parent) {
  const node = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  if (parent) parent.appendChild(node);
  return node;
}

// ---- the grid ------------------------------------------------------------------------------

function buildGrid() {
  const table = $('grid');
  table.textContent = '';
  const head = table.createTHead().insertRow();
  head.appendChild(document.createElement('th'));
  for (const second of app.info.phonemes) {
    const th = document.createElement('th');
    th.textContent = second;
    head.appendChild(th);
  }
  const body = table.createTBody();
  for (const first of app.info.phonemes) {
    const row = body.insertRow();
    const th = document.createElement('th');
    th.textContent = first;
    row.appendChild(th);
    for (const second of app.info.phonemes) {
      const button = document.createElement('button');
      button.dataset.pair = first + '-' + second;
      button.title = first + ' \u2013 ' + second;
      button.addEventListener('click', () => openPair(first, second).catch(showError));
      row.insertCell().appendChild(button);
    }
  }
  paintGrid();
}

function paintGrid() {
  const states = new Map(app.info.bigrams.map((b) => [b.name, b.state]));
  for (const button of $('grid').querySelectorAll('button')) {
    const pair = button.dataset.pair;
    button.className = states.get(pair) || 'generated';
    if (app.used.has(pair)) button.classList.add('used');
    if (pair === app.pair) button.classList.add('current');
  }
  const unsaved = app.info.unsaved;
  setStatus(unsaved ? unsaved + ' bigram' + (unsaved > 1 ? 's' : '') + ' not saved' : 'all saved');
}

function noteState(bigram) {
  const entry = app.info.bigrams.find((b) => b.name === bigram.name);
  if (entry) entry.state = bigram.state;
  app.info.unsaved = bigram.unsaved;
  paintGrid();
}

// ---- one bigram's curves -------------------------------------------------------------------

const PLOT = { width: 560, height: 64, left: 92, right: 10, top: 6, bottom: 6 };
const plotW = () => PLOT.width - PLOT.left - PLOT.right;
const plotH = () => PLOT.height - PLOT.top - PLOT.bottom;
const xOf = (t) => PLOT.left + t * plotW();
const yOf = (v) => PLOT.top + (1 - v) * plotH();

async function openPair(first, second) {
  app.pair = first + '-' + second;
  app.selected = null;
  app.bigram = await api('GET', '/api/bigrams/' + first + '/' + second);
  $('pair-title').textContent = first + ' \u2013 ' + second + '  (' + app.bigram.state + ')';
  drawCurves();
  showPoint();
  noteState(app.bigram);
}

function drawCurves() {
  const box = $('curves');
  box.textContent = '';
  for (const pose of app.info.poses) {
    const svg = el('svg', { width: PLOT.width, height: PLOT.height, 'data-pose': pose }, box);
    drawPose(svg, pose);
  }
}

function drawPose(svg, pose) {
  svg.textContent = '';
  const rect = el('rect', { class: 'box', x: PLOT.left, y: PLOT.top, width: plotW(), height: plotH() }, svg);
  rect.addEventListener('click', (e) => addPoint(svg, pose, e));
  el('text', { class: 'pose-name', x: 4, y: PLOT.top + plotH() / 2 + 4 }, svg).textContent = pose;
  const names = [app.bigram.first, app.bigram.second];
  app.info.centres.forEach((c, i) => {
    el('line', { class: 'centre', x1: xOf(c), x2: xOf(c), y1: PLOT.top, y2: PLOT.top + plotH() }, svg);
    el('text', { class: 'centre-label', x: xOf(c) + 3, y: PLOT.top + 10 }, svg).textContent = names[i];
  });
  const samples = app.bigram.curves[pose];
  const spline = samples.map((v, i) => xOf(i / (samples.length - 1)) + ',' + yOf(v)).join(' ');
  el('polyline', { class: 'spline', points: spline }, svg);
  const points = app.bigram.poses[pose];
  el('polyline', { class: 'polygon', points: points.map(([t, v]) => xOf(t) + ',' + yOf(v)).join(' ') }, svg);
  points.forEach(([t, v], index) => {
    const selected = app.selected && app.selected.pose === pose && app.selected.index === index;
    const c = el('circle', {
      class: 'point' + (selected ? ' selected' : ''), cx: xOf(t), cy: yOf(v), r: 5,
      'data-pose': pose, 'data-index': index,
    }, svg);
    c.addEventListener('pointerdown', (e) => startDrag(svg, pose, index, e));
    c.addEventListener('click', (e) => e.stopPropagation());
    c.addEventListener('dblclick', (e) => { e.stopPropagation(); removePoint(pose, index); });
  });
}

function redrawPose(pose) {
  const svg = $('curves').querySelector('svg[data-pose="' + pose + '"]');
  if (svg) drawPose(svg, pose);
}

// Pointer position in the plot's (time, value), clamped to the box.
function plotPosition(svg, event) {
  const p = svg.createSVGPoint();
  p.x = event.clientX;
  p.y = event.clientY;
  const q = p.matrixTransform(svg.getScreenCTM().inverse());
  return [clamp((q.x - PLOT.left) / plotW(), 0, 1), clamp(1 - (q.y - PLOT.top) / plotH(), 0, 1)];
}

const copyPoses = (poses) => JSON.parse(JSON.stringify(poses));
function remember() {
  app.undo.push({ pair: app.pair, poses: copyPoses(app.bigram.poses) });
  app.redo = [];
  updateUndoButtons();
}

function startDrag(svg, pose, index, event) {
  event.preventDefault();
  app.selected = { pose, index };
  app.drag = { pose, index, svg, before: copyPoses(app.bigram.poses), moved: false };
  event.target.setPointerCapture(event.pointerId);
  event.target.addEventListener('pointermove', moveDrag);
  event.target.addEventListener('pointerup', endDrag, { once: true });
  // The circle holds the pointer capture: mark it, never redraw it away mid-drag.
  for (const c of $('curves').querySelectorAll('circle.selected')) c.classList.remove('selected');
  event.target.classList.add('selected');
  showPoint();
}

function moveDrag(event) {
  const d = app.drag;
  if (!d) return;
  const points = app.bigram.poses[d.pose];
  let [t, v] = plotPosition(d.svg, event);
  const last = points.length - 1;
  if (d.index === 0) t = 0;
  else if (d.index === last) t = 1;
  else t = clamp(t, points[d.index - 1][0] + 0.001, points[d.index + 1][0] - 0.001);
  points[d.index] = [round3(t), round3(v)];
  d.moved = true;
  // Only the dragged point moves here; the circle keeps the pointer capture.
  event.target.setAttribute('cx', xOf(t));
  event.target.setAttribute('cy', yOf(v));
  d.svg.querySelector('.polygon').setAttribute(
    'points', points.map(([pt, pv]) => xOf(pt) + ',' + yOf(pv)).join(' '));
  send();
}

function endDrag(event) {
  const d = app.drag;
  event.target.removeEventListener('pointermove', moveDrag);
  app.drag = null;
  if (!d || !d.moved) return;
  app.undo.push({ pair: app.pair, poses: d.before });
  app.redo = [];
  updateUndoButtons();
  send();
}

function addPoint(svg, pose, event) {
  const [t, v] = plotPosition(svg, event);
  const points = app.bigram.poses[pose];
  const at = points.findIndex(([pt]) => pt > t);
  if (at <= 0 || t - points[at - 1][0] < 0.002 || points[at][0] - t < 0.002) return;
  remember();
  points.splice(at, 0, [round3(t), round3(v)]);
  app.selected = { pose, index: at };
  showPoint();
  redrawPose(pose);
  send();
}

function removePoint(pose, index) {
  const points = app.bigram.poses[pose];
  if (index === 0 || index === points.length - 1) {
    showError('the end points (time 0 and 1) stay; drag them up or down instead');
    return;
  }
  remember();
  points.splice(index, 1);
  app.selected = null;
  showPoint();
  redrawPose(pose);
  send();
}

// PUTs go one at a time; moves that arrive meanwhile are sent together afterwards.
async function send() {
  if (app.sending) { app.pending = true; return; }
  app.sending = true;
  const pair = app.pair;
  try {
    do {
      app.pending = false;
      const [first, second] = [app.bigram.first, app.bigram.second];
      const answer = await api('PUT', '/api/bigrams/' + first + '/' + second, { poses: app.bigram.poses });
      if (pair !== app.pair) break;
      app.bigram.curves = answer.curves;
      app.bigram.state = answer.state;
      if (!app.drag && !app.pending) app.bigram.poses = answer.poses;
      noteState(answer);
      showError(null);
    } while (app.pending);
  } catch (e) {
    showError(e);
    const selected = app.selected;
    await openPair(app.bigram.first, app.bigram.second).catch(showError);  // the server's truth
    app.selected = selected;
  } finally {
    app.sending = false;
  }
  if (!app.drag) {
    $('pair-title').textContent = app.bigram.first + ' \u2013 ' + app.bigram.second + '  (' + app.bigram.state + ')';
    drawCurves();
  } else {
    const spline = app.drag.svg.querySelector('.spline');
    const samples = app.bigram.curves[app.drag.pose];
    spline.setAttribute('points', samples.map((v, i) => xOf(i / (samples.length - 1)) + ',' + yOf(v)).join(' '));
  }
  showPoint();
}

// ---- numeric entry -------------------------------------------------------------------------

function showPoint() {
  const s = app.selected;
  const ok = s && app.bigram && app.bigram.poses[s.pose] && app.bigram.poses[s.pose][s.index];
  for (const id of ['point-time', 'point-value', 'point-set']) $(id).disabled = !ok;
  if (!ok) {
    $('point-name').textContent = 'no point selected';
    $('point-time').value = $('point-value').value = '';
    return;
  }
  const [t, v] = app.bigram.poses[s.pose][s.index];
  $('point-name').textContent = s.pose + ' point ' + s.index;
  $('point-time').value = t;
  $('point-value').value = v;
}

// Sent as typed: the server says what is wrong (out of range, times not increasing).
function setPoint() {
  const s = app.selected;
  if (!s) return;
  remember();
  app.bigram.poses[s.pose][s.index] = [Number($('point-time').value), Number($('point-value').value)];
  send();
}

// ---- undo / redo ---------------------------------------------------------------------------

function updateUndoButtons() {
  $('undo').disabled = app.undo.length === 0;
  $('redo').disabled = app.redo.length === 0;
}

async function step(from, to) {
  const entry = from.pop();
  if (!entry) return;
  const [first, second] = entry.pair.split('-');
  if (entry.pair !== app.pair) await openPair(first, second);
  to.push({ pair: app.pair, poses: copyPoses(app.bigram.poses) });
  app.bigram.poses = entry.poses;
  app.selected = null;
  updateUndoButtons();
  await send();
}

// ---- save ----------------------------------------------------------------------------------

async function save() {
  const answer = await api('POST', '/api/save', {});
  app.info = await api('GET', '/api/bigrams');
  paintGrid();
  if (app.bigram) {
    const b = app.info.bigrams.find((x) => x.name === app.pair);
    $('pair-title').textContent = app.bigram.first + ' \u2013 ' + app.bigram.second + '  (' + b.state + ')';
  }
  setStatus('saved ' + answer.saved + ' bigram' + (answer.saved === 1 ? '' : 's') + ' to ' + answer.file);
  showError(null);
}

// ---- preview -------------------------------------------------------------------------------

function runtimeSteps() {
  return {
    smoothing: $('step-smoothing').checked,
    constraints: $('step-constraints').checked,
    speed_limits: $('step-speed').checked,
  };
}

async function preview(event) {
  event.preventDefault();
  setStatus('speaking\u2026');
  showPreview(await api('POST', '/api/preview', { text: $('sentence').value, ...runtimeSteps() }));
}

function readAsDataUrl(file) {
  return new Promise((resolve, reject) => {
    const reader = new FileReader();
    reader.onload = () => resolve(reader.result);
    reader.onerror = () => reject(reader.error);
    reader.readAsDataURL(file);
  });
}

// A recording goes up as its bytes (a data: URI in the JSON): the editor never opens a path.
async function previewRecording(event) {
  event.preventDefault();
  const file = $('recording').files[0];
  if (!file) throw new Error('pick a recording (WAV, FLAC or OGG) first');
  setStatus(($('words').value.trim() ? 'aligning ' : 'analysing ') + file.name + '\u2026');
  const body = { wav: await readAsDataUrl(file), ...runtimeSteps() };
  if ($('words').value.trim()) body.text = $('words').value;
  showPreview(await api('POST', '/api/preview', body));
}

// The puppet follows the page's audio: it starts where the audio starts and stops with it.
function perform(body) {
  if (!app.info.puppet || !app.preview) return;
  api('POST', '/api/perform', body)
    .then((r) => { if (r.stopped_early) showError(new Error('puppet: lipsyncd stopped the stream: ' + r.stopped_early)); })
    .catch(showError);
}

function showPreview(p) {
  app.preview = p;
  app.used = new Set(p.pairs);
  paintGrid();
  drawTimeline();
  const audio = $('audio');
  audio.src = p.audio;
  audio.currentTime = 0;
  drawCursor(0);
  audio.play().catch(() => {});  // no sound device: the cursor still follows seeking
  const how = { 'espeak-ng': '', aligned: ', words aligned', 'audio-only': ', audio-only analysis' };
  setStatus('preview: ' + p.schedule.length + ' phonemes, ' + p.duration.toFixed(2) + ' s' + how[p.source]);
  document.body.dataset.preview = 'ready';
  document.body.dataset.source = p.source;
  showError(p.warnings.length ? p.warnings.join('\n') : null);
}

const TL = { left: 86, right: 10, top: 4, strip: 20, lane: 22 };
function tlX(t) {
  const width = $('timeline').width.baseVal.value;
  return TL.left + (t / app.preview.duration) * (width - TL.left - TL.right);
}

function drawTimeline() {
  const p = app.preview;
  const svg = $('timeline');
  const height = TL.top + TL.strip + p.weights.poses.length * TL.lane + 4;
  svg.setAttribute('height', height);
  svg.textContent = '';
  for (const s of p.schedule) {
    el('rect', { class: 'segment', x: tlX(s.start), y: TL.top, width: Math.max(1, tlX(s.end) - tlX(s.start)), height: TL.strip - 4 }, svg);
    if (s.phoneme !== 'sil')
      el('text', { class: 'segment-label', x: (tlX(s.start) + tlX(s.end)) / 2, y: TL.top + 12 }, svg).textContent = s.phoneme;
  }
  if (app.pair) markPairSegments(svg);
  p.weights.poses.forEach((pose, i) => {
    const base = TL.top + TL.strip + (i + 1) * TL.lane - 3;
    el('text', { class: 'pose-name', x: 4, y: base - 4 }, svg).textContent = pose;
    el('line', { class: 'lane-base', x1: TL.left, x2: tlX(p.duration), y1: base, y2: base }, svg);
    const pts = p.weights.values[i].map((v, f) => tlX(p.weights.times[f]) + ',' + (base - v * (TL.lane - 4)));
    el('polyline', { class: 'lane-line', points: pts.join(' ') }, svg);
  });
  el('line', { class: 'cursor', id: 'cursor', x1: TL.left, x2: TL.left, y1: 0, y2: height }, svg);
}

// The segments of the pair being edited, where the sentence has it.
function markPairSegments(svg) {
  const [first, second] = app.pair.split('-');
  const segs = app.preview.schedule;
  const rects = svg.querySelectorAll('rect.segment');
  for (let i = 0; i + 1 < segs.length; ++i)
    if (segs[i].phoneme === first && segs[i + 1].phoneme === second) {
      rects[i].classList.add('pair');
      rects[i + 1].classList.add('pair');
    }
}

function weightsAt(time) {
  const w = app.preview.weights;
  if (!w.times.length) return w.poses.map(() => 0);
  const f = clamp(Math.round((time - w.times[0]) * w.rate), 0, w.times.length - 1);
  return w.values.map((row) => row[f]);
}

function drawCursor(time) {
  if (!app.preview) return;
  const c = $('cursor');
  if (c) { c.setAttribute('x1', tlX(time)); c.setAttribute('x2', tlX(time)); }
  drawMouth(mouthShape(weightsAt(time)));
}

function followAudio() {
  const audio = $('audio');
  drawCursor(audio.currentTime);
  if (!audio.paused && !audio.ended) requestAnimationFrame(followAudio);
}

function seek(event) {
  if (!app.preview) return;
  const svg = $('timeline');
  const p = svg.createSVGPoint();
  p.x = event.clientX;
  const x = p.matrixTransform(svg.getScreenCTM().inverse()).x;
  const width = svg.width.baseVal.value;
  const t = clamp((x - TL.left) / (width - TL.left - TL.right), 0, 1) * app.preview.duration;
  $('audio').currentTime = t;
  drawCursor(t);
}

// ---- the 2-D mouth -------------------------------------------------------------------------

// Drawing parameters from pose weights, as config/editor/mouth.toml says.
function mouthShape(weights) {
  const m = app.info.mouth;
  const sum = m.neutral.slice();
  app.info.poses.forEach((pose, i) => {
    const amounts = m.poses[pose];
    if (amounts) amounts.forEach((a, k) => { sum[k] += a * (weights[i] || 0); });
  });
  const shape = {};
  m.parameters.forEach((name, k) => { shape[name] = clamp(sum[k], -1, 1); });
  return shape;
}

function drawMouth(s) {
  const svg = $('mouth');
  svg.textContent = '';
  const cx = 100, cy = 70;
  const jaw = clamp(s.jaw || 0, 0, 1), round = clamp(s.round || 0, 0, 1);
  const press = clamp(s.press || 0, 0, 1), bite = clamp(s.bite || 0, 0, 1);
  const half = 52 * (1 + 0.25 * (s.width || 0)) * (1 - 0.45 * round);
  const gap = (50 * jaw * (1 - 0.75 * bite) + 10 * round) * (1 - press);
  const corner = cy + gap * 0.15;
  const top = cy - gap * 0.35, bottom = cy + gap * 0.65;
  const ctl = (edge) => 2 * edge - corner;  // a quadratic's control point for that mid height
  const opening = `M${cx - half},${corner} Q${cx},${ctl(top)} ${cx + half},${corner} ` +
                  `Q${cx},${ctl(bottom)} ${cx - half},${corner} Z`;
  const defs = el('defs', {}, svg);
  el('path', { d: opening }, el('clipPath', { id: 'mouth-opening' }, defs));
  el('path', { d: opening, fill: '#4a1018' }, svg);
  const inside = el('g', { 'clip-path': 'url(#mouth-opening)' }, svg);
  // Tongue: the tip rises to the ridge (tongue_up), drops (tongue_down), draws back (tongue_back).
  const up = clamp(s.tongue_up || 0, 0, 1), down = clamp(s.tongue_down || 0, 0, 1);
  const back = clamp(s.tongue_back || 0, 0, 1);
  const tongueY = bottom - 4 - (bottom - top - 10) * up * 0.8 + 6 * down;
  el('ellipse', { cx, cy: tongueY + 10, rx: half * (0.7 - 0.3 * back), ry: 14 - 4 * back,
                  fill: back > 0.3 ? '#b04a5a' : '#d9707e' }, inside);
  el('rect', { x: cx - half * 0.7, y: top - 6, width: half * 1.4, height: 12, rx: 3, fill: '#fffef6' }, inside);
  el('rect', { x: cx - half * 0.6, y: bottom - 5 - 6 * bite, width: half * 1.2, height: 10, rx: 3,
               fill: '#f4f1e6' }, inside);
  // Lips: bands around the opening; the lower lip tucks under the upper teeth for bite.
  const lipTop = top - 12 - 4 * round, lipBottom = bottom + 13 + 3 * round - 6 * bite;
  el('path', { d: `M${cx - half - 6},${corner} Q${cx},${ctl(lipTop)} ${cx + half + 6},${corner} ` +
                  `Q${cx},${ctl(top)} ${cx - half - 6},${corner} Z`, fill: '#c0505e' }, svg);
  el('path', { d: `M${cx - half - 6},${corner} Q${cx},${ctl(bottom)} ${cx + half + 6},${corner} ` +
                  `Q${cx},${ctl(lipBottom)} ${cx - half - 6},${corner} Z`, fill: '#cf5f6c' }, svg);
}

// ---- start ---------------------------------------------------------------------------------

async function start() {
  app.info = await api('GET', '/api/bigrams');
  $('file').textContent = app.info.character
    ? 'character ' + app.info.character.split('/').pop() + ' on ' + app.info.base
    : app.info.base + ' (no character file: saving is off)';
  $('save').disabled = !app.info.character;
  buildGrid();
  drawMouth(mouthShape(app.info.poses.map(() => 0)));
  $('undo').addEventListener('click', () => step(app.undo, app.redo).catch(showError));
  $('redo').addEventListener('click', () => step(app.redo, app.undo).catch(showError));
  $('save').addEventListener('click', () => save().catch(showError));
  $('point-set').addEventListener('click', setPoint);
  for (const id of ['point-time', 'point-value'])
    $(id).addEventListener('keydown', (e) => { if (e.key === 'Enter') setPoint(); });
  $('preview-form').addEventListener('submit', (e) => preview(e).catch(showError));
  $('recording-form').addEventListener('submit', (e) => previewRecording(e).catch(showError));
  $('puppet').textContent = app.info.puppet ? 'moves the puppet \u2018' + app.info.puppet + '\u2019' : '';
  $('audio').addEventListener('play', () => {
    perform({ from: $('audio').currentTime });
    requestAnimationFrame(followAudio);
  });
  $('audio').addEventListener('pause', () => perform({ stop: true }));
  $('audio').addEventListener('seeked', () => {
    drawCursor($('audio').currentTime);
    if (!$('audio').paused) perform({ from: $('audio').currentTime });
  });
  $('timeline').addEventListener('click', seek);
  document.addEventListener('keydown', (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.target.tagName === 'INPUT') return;
    const key = e.key.toLowerCase();
    if (key === 'z' && !e.shiftKey) { e.preventDefault(); step(app.undo, app.redo).catch(showError); }
    if (key === 'y' || (key === 'z' && e.shiftKey)) { e.preventDefault(); step(app.redo, app.undo).catch(showError); }
  });
  document.body.dataset.ready = 'yes';
}

start().catch(showError);
