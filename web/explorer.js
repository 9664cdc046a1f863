// gonio explorer: the page of `gonio explore` and the module of the Jupyter widget `gonio.explore`.
// It draws only numbers the explorer gives (gonio::explore, the same functions as `gonio plot`); no
// reflectance math here. Plain modern JS: SVG for curves, canvas for the 3-D lobe and the slice, no
// libraries, no build step. The transport is a function (path, params) -> {status, type, body}: fetch in
// the browser, widget messages in Jupyter.

const COLOURS = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf'];
const SVGNS = 'http://www.w3.org/2000/svg';

/** The browser's transport: GET requests to the server the page came from. */
export function fetchTransport(base = '') {
  return async (path, params) => {
    const r = await fetch(base + path + '?' + new URLSearchParams(params));
    return { status: r.status, type: r.headers.get('content-type') || '', body: new Uint8Array(await r.arrayBuffer()) };
  };
}

/** Jupyter's transport: custom widget messages answered by the Python side (same gonio::explore code). */
export function widgetTransport(model) {
  let next = 0;
  const pending = new Map();
  model.on('msg:custom', (msg, buffers) => {
    const resolve = pending.get(msg.id);
    if (!resolve) return;
    pending.delete(msg.id);
    const b = buffers && buffers[0];
    const body = b ? new Uint8Array(b.buffer, b.byteOffset, b.byteLength) : new Uint8Array();
    resolve({ status: msg.status, type: msg.type, body });
  });
  return (path, params) => new Promise((resolve) => {
    const id = ++next;
    pending.set(id, resolve);
    model.send({ id, path, query: new URLSearchParams(params).toString() });
  });
}

const text = (bytes) => new TextDecoder().decode(bytes);
const h = (tag, attrs = {}, ...children) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c);
  return e;
};
const s = (tag, attrs = {}) => {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
};

function debounce(fn, ms) {
  let t = null;
  return (...a) => { clearTimeout(t); t = setTimeout(() => fn(...a), ms); };
}

function download(name, blob) {
  const a = h('a', { href: URL.createObjectURL(blob), download: name });
  document.body.append(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}

const DEFAULT_STATE = {
  layers: [{ spec: { type: 'roughconductor', distribution: 'ggx', alpha: 0.2 }, colour: COLOURS[0], visible: true }],
  sel: 0, solo: -1, theta_o: 30, channel: 'lum', log: false, light: 'env', dir: [0.6, 0.6, 0.5], phi_d: 90,
};

/**
 * Build the explorer in `root`. `api(path, params)` answers requests; `options.state` is the initial state
 * (else the URL's hash, else a default), `options.onState(state, spec)` hears every change.
 */
export function mount(root, api, options = {}) {
  const app = new Explorer(root, api, options);
  root.gxExplorer = app; // for scripts and tests: the state and the numbers drawn
  app.start();
  return app;
}

class Explorer {
  constructor(root, api, options) {
    this.root = root;
    this.api = api;
    this.options = options;
    this.cache = new Map(); // request key -> parsed JSON of a plot
    this.models = [];
    this.files = [];
    this.tokens = { plots: 0, sphere: 0, verify: 0 };
    // Names this page to the server, whose lit sphere renders are ordered per client by `seq` (the token).
    this.client = Math.random().toString(36).slice(2);
    this.view = { yaw: -0.6, pitch: 0.5 };
    this.state = structuredClone(DEFAULT_STATE);
    this.data = {}; // per panel: the models shown and their numbers
  }

  async start() {
    this.root.classList.add('gx');
    this.root.replaceChildren(h('p', {}, 'loading…'));
    const r = await this.api('/api/models', {});
    const info = JSON.parse(text(r.body));
    this.models = info.models;
    this.files = info.files;
    this.fitModels = info.fit_models;
    this.hasEnvironment = !!info.environment;
    let state = null;
    try {
      if (this.options.state) state = JSON.parse(this.options.state);
      else if (!this.options.onState && location.hash.length > 1) state = JSON.parse(decodeURIComponent(location.hash.slice(1)));
    } catch (e) { state = null; }
    if (state && Array.isArray(state.layers) && state.layers.length) this.state = Object.assign(structuredClone(DEFAULT_STATE), state);
    else if (info.initial.length) {
      this.state.layers = info.initial.map((t, i) => ({ spec: JSON.parse(t), colour: COLOURS[i % COLOURS.length], visible: true }));
    }
    this.build();
    this.changed();
  }

  get layer() { return this.state.layers[this.state.sel]; }
  shown() {
    return this.state.layers.map((l, i) => ({ l, i })).filter(({ l, i }) => (this.state.solo >= 0 ? i === this.state.solo : l.visible));
  }
  label(l) {
    const file = l.spec.filename ? ' ' + String(l.spec.filename).split('/').pop() : '';
    return l.label || (l.spec.type + file);
  }

  // ---------- layout ----------
  build() {
    const panel = (id, title, body, tools = []) => h('section', { class: 'gx-panel', id: 'gx-' + id },
      h('header', {}, h('h3', {}, title), h('span', { class: 'gx-tools' }, tools)), body);
    this.el = {};
    this.el.layers = h('ul', { class: 'gx-layers' });
    this.el.addType = h('select', {}, this.models.map((m) => h('option', { value: m.plugin, title: m.about }, m.plugin)));
    this.el.addFile = h('select', {}, h('option', { value: '' }, this.files.length ? 'measured file…' : '(no --data folder)'),
      this.files.map((f) => h('option', { value: f }, f.split('/').pop())));
    this.el.form = h('div', { class: 'gx-form' });
    this.el.json = h('textarea', { rows: 4, spellcheck: 'false', class: 'gx-json', onchange: () => this.jsonEdited() });
    this.el.error = h('div', { class: 'gx-error', role: 'alert' });
    this.el.verify = h('div', { class: 'gx-verify' });
    this.el.fitModel = h('select', {}, (this.fitModels || []).map((m) => h('option', { value: m.name, title: m.about }, m.name)));
    this.el.fitStatus = h('span', { class: 'gx-note' });
    const st = this.state;
    this.el.theta = h('input', { type: 'range', min: 0, max: 89, step: 1, value: st.theta_o, oninput: (e) => { st.theta_o = +e.target.value; this.changed(); } });
    this.el.thetaText = h('span', { class: 'gx-note' });
    this.el.phi = h('input', { type: 'range', class: 'gx-phi-d', min: 0, max: 180, step: 1, value: st.phi_d, oninput: (e) => { st.phi_d = +e.target.value; this.changed(); } });
    this.el.phiText = h('span', { class: 'gx-note' });
    const view = h('div', { class: 'gx-view' },
      h('label', {}, 'θo ', this.el.theta, this.el.thetaText),
      h('label', {}, 'φd of the slice ', this.el.phi, this.el.phiText),
      h('label', {}, 'channel ', h('select', { onchange: (e) => { st.channel = e.target.value; this.changed(); } },
        ['lum', 'r', 'g', 'b'].map((c) => h('option', { value: c, selected: c === st.channel }, c)))),
      h('label', {}, h('input', { type: 'checkbox', checked: st.log, onchange: (e) => { st.log = e.target.checked; this.draw(); this.saveState(); } }), ' log scale'));
    const side = h('aside', { class: 'gx-side' },
      h('h2', {}, 'gonio explorer'),
      h('h4', {}, 'Models'), this.el.layers,
      h('div', { class: 'gx-row' }, this.el.addType, h('button', { onclick: () => this.addLayer({ type: this.el.addType.value }) }, 'add')),
      h('div', { class: 'gx-row' }, this.el.addFile, h('button', {
        onclick: () => {
          const f = this.el.addFile.value;
          if (f) this.addLayer({ type: f.endsWith('.binary') ? 'merl' : 'measured', filename: f });
        },
      }, 'add')),
      h('h4', {}, 'Parameters of the selected model'), this.el.form,
      h('details', {}, h('summary', {}, 'JSON (any model, nested ones too)'), this.el.json),
      this.el.error,
      h('h4', {}, 'View'), view,
      h('h4', {}, 'Verification (quick)'), this.el.verify,
      h('h4', {}, 'Fit an analytic model to the selected one'),
      h('div', { class: 'gx-row' }, this.el.fitModel, h('button', { onclick: () => this.fit() }, 'fit'), this.el.fitStatus),
      h('h4', {}, 'Export'),
      h('div', { class: 'gx-row' },
        h('button', { onclick: () => this.exportModel('xml') }, 'Mitsuba XML'),
        h('button', { onclick: () => this.exportModel('json') }, 'JSON'),
        this.options.onState ? null : h('button', { onclick: () => navigator.clipboard && navigator.clipboard.writeText(location.href) }, 'copy link')));
    this.el.polar = s('svg', { viewBox: '0 0 640 205', class: 'gx-svg' });
    this.el.albedo = s('svg', { viewBox: '0 0 420 300', class: 'gx-svg' });
    this.el.lobe = h('canvas', { width: 420, height: 330, class: 'gx-canvas' });
    this.el.slice = h('canvas', { width: 420, height: 330, class: 'gx-canvas' });
    this.el.sphere = h('img', { class: 'gx-sphere', alt: 'lit sphere', draggable: 'false' });
    this.el.sphereNote = h('span', { class: 'gx-note' });
    this.el.light = h('select', { onchange: (e) => { st.light = e.target.value; this.changedSphere(); } },
      [['env', this.hasEnvironment ? 'environment map' : 'built-in sky'], ['sky', 'built-in sky'], ['furnace', 'white furnace'], ['dir', 'directional light (drag)']]
        .map(([v, t]) => h('option', { value: v, selected: v === st.light }, t)));
    const exp = (name, el) => [
      h('button', { class: 'gx-small', onclick: () => this.exportFigure(name, el, 'svg') }, 'SVG'),
      h('button', { class: 'gx-small', onclick: () => this.exportFigure(name, el, 'png') }, 'PNG')];
    const main = h('main', { class: 'gx-main' },
      panel('polar', 'f·cos θi: plane of incidence | perpendicular plane', this.el.polar, exp('polar', this.el.polar)),
      panel('lobe', '3-D lobe (drag to turn)', this.el.lobe, exp('lobe', this.el.lobe).slice(1)),
      panel('slice', 'θh × θd slice of the selected model', this.el.slice, exp('slice', this.el.slice).slice(1)),
      panel('albedo', 'directional albedo and white furnace', this.el.albedo, exp('albedo', this.el.albedo)),
      panel('sphere', 'lit sphere (path traced)', h('div', {}, this.el.sphere, h('div', {}, this.el.light, ' ', this.el.sphereNote))));
    this.root.replaceChildren(h('div', { class: 'gx-app' }, side, main));
    this.dragLobe();
    this.dragLight();
    this.buildLayers();
    this.buildForm();
  }

  buildLayers() {
    const st = this.state;
    this.el.layers.replaceChildren(...st.layers.map((l, i) => h('li', { class: i === st.sel ? 'gx-selected' : '' },
      h('input', { type: 'color', value: l.colour, title: 'colour', oninput: (e) => { l.colour = e.target.value; this.draw(); this.saveState(); } }),
      h('input', { type: 'checkbox', checked: l.visible, title: 'shown', onchange: (e) => { l.visible = e.target.checked; this.changed(); } }),
      h('span', { class: 'gx-name', onclick: () => { st.sel = i; this.buildLayers(); this.buildForm(); this.changed(); } }, this.label(l)),
      h('button', { class: 'gx-small' + (st.solo === i ? ' gx-on' : ''), title: 'solo', onclick: () => { st.solo = st.solo === i ? -1 : i; this.buildLayers(); this.changed(); } }, 'S'),
      h('button', { class: 'gx-small', title: 'remove', disabled: st.layers.length === 1, onclick: () => this.removeLayer(i) }, '×'))));
  }

  addLayer(spec, label) {
    const used = new Set(this.state.layers.map((l) => l.colour));
    const colour = COLOURS.find((c) => !used.has(c)) || COLOURS[this.state.layers.length % COLOURS.length];
    this.state.layers.push({ spec, colour, visible: true, label });
    this.state.sel = this.state.layers.length - 1;
    this.buildLayers();
    this.buildForm();
    this.changed();
  }

  removeLayer(i) {
    const st = this.state;
    st.layers.splice(i, 1);
    if (st.solo === i) st.solo = -1; else if (st.solo > i) st.solo -= 1;
    st.sel = Math.min(st.sel >= i && st.sel > 0 ? st.sel - 1 : st.sel, st.layers.length - 1);
    this.buildLayers();
    this.buildForm();
    this.changed();
  }

  // ---------- the form, from the model's parameter table ----------
  buildForm() {
    const l = this.layer;
    const model = this.models.find((m) => m.plugin === l.spec.type);
    this.el.json.value = JSON.stringify(l.spec);
    this.fields = new Map();
    const typeSelect = h('select', {
      onchange: (e) => { l.spec = { type: e.target.value }; l.label = undefined; this.buildLayers(); this.buildForm(); this.changed(); },
    }, this.models.map((m) => h('option', { value: m.plugin, selected: m.plugin === l.spec.type }, m.plugin)));
    const rows = [h('div', { class: 'gx-field' }, h('label', {}, 'type'), typeSelect, model ? h('div', { class: 'gx-note' }, model.about) : null)];
    for (const p of model ? model.params : []) {
      if (p.kind === 'nested') {
        rows.push(h('div', { class: 'gx-field gx-note' }, `nested BSDF (${p.meaning}): edit the JSON`));
        continue;
      }
      for (const name of p.names) rows.push(this.field(name, p));
    }
    this.el.form.replaceChildren(...rows);
  }

  field(name, p) {
    const spec = this.layer.spec;
    const has = Object.prototype.hasOwnProperty.call(spec, name);
    const value = has ? spec[name] : p.default;
    const message = h('div', { class: 'gx-field-error', role: 'alert' });
    const set = (v) => { spec[name] = v; row.classList.add('gx-set'); this.el.json.value = JSON.stringify(spec); this.changed(); };
    const reset = h('button', { class: 'gx-small', title: `back to the default (${p.default_text})`, onclick: () => { delete spec[name]; this.buildForm(); this.changed(); } }, '↺');
    let control;
    const r = p.range || {};
    if ((p.kind === 'float' || p.kind === 'int') && r.min !== null && r.max !== null && r.min !== undefined) {
      const lo = r.min + (r.min_open ? 1e-3 * (r.max - r.min) : 0);
      const hi = r.max - (r.max_open ? 1e-3 * (r.max - r.min) : 0);
      const scale = sliderScale(lo, hi, p.kind === 'int');
      const num = h('input', { type: 'number', step: 'any', value: value ?? '', class: 'gx-num' });
      const slider = h('input', { type: 'range', min: 0, max: 1000, step: 1, value: value === undefined || value === null ? 500 : scale.toSlider(+value) });
      slider.addEventListener('input', () => { const v = scale.fromSlider(+slider.value); num.value = v; set(v); });
      num.addEventListener('change', () => { const v = Number(num.value); if (num.value.trim() !== '' && !Number.isNaN(v)) { slider.value = scale.toSlider(v); set(v); } });
      control = [slider, num];
    } else if (p.kind === 'float' || p.kind === 'int') {
      const num = h('input', { type: 'number', step: 'any', value: value ?? '', class: 'gx-num' });
      num.addEventListener('change', () => set(Number(num.value)));
      control = [num];
    } else if (p.kind === 'rgb' && r.max === 1) {
      const rgb = Array.isArray(value) ? value : [value ?? 0, value ?? 0, value ?? 0];
      const colour = h('input', { type: 'color', value: toHex(rgb) });
      const num = h('input', { type: 'text', value: Array.isArray(value) ? value.join(', ') : (value ?? ''), class: 'gx-num', title: 'a number or r, g, b' });
      colour.addEventListener('input', () => { const v = fromHex(colour.value); num.value = v.join(', '); set(v); });
      num.addEventListener('change', () => { const v = parseNumbers(num.value); colour.value = toHex(Array.isArray(v) ? v : [v, v, v]); set(v); });
      control = [colour, num];
    } else if (p.kind === 'rgb' || p.kind === 'list') {
      const t = h('input', { type: 'text', value: Array.isArray(value) ? value.join(', ') : (value ?? ''), placeholder: p.default_text, class: 'gx-text' });
      t.addEventListener('change', () => set(p.kind === 'list' ? [].concat(parseNumbers(t.value)) : parseNumbers(t.value)));
      control = [t];
    } else if (p.kind === 'enum') {
      const sel = h('select', {}, p.choices.map((c) => h('option', { value: c, selected: c === value }, c)));
      sel.addEventListener('change', () => set(sel.value));
      control = [sel];
    } else if (p.kind === 'bool') {
      const c = h('input', { type: 'checkbox', checked: !!value });
      c.addEventListener('change', () => set(c.checked));
      control = [c];
    } else if (p.kind === 'file') {
      const sel = h('select', {}, h('option', { value: '' }, '—'), this.files.map((f) => h('option', { value: f, selected: f === value }, f.split('/').pop())));
      sel.addEventListener('change', () => set(sel.value));
      control = [sel];
    } else {
      const t = h('input', { type: 'text', value: value ?? '', placeholder: p.default_text, class: 'gx-text' });
      t.addEventListener('change', () => { const v = t.value.trim(); set(p.kind === 'ior' && v !== '' && !Number.isNaN(Number(v)) ? Number(v) : v); });
      control = [t];
    }
    const row = h('div', { class: 'gx-field' + (has ? ' gx-set' : ''), 'data-param': name },
      h('label', { title: p.meaning }, name), control, reset, h('div', { class: 'gx-note' }, `${p.meaning} (default ${p.default_text})`), message);
    this.fields.set(name, message);
    return row;
  }

  jsonEdited() {
    try {
      const spec = JSON.parse(this.el.json.value);
      if (typeof spec !== 'object' || !spec || typeof spec.type !== 'string') throw new Error('a JSON object with a "type"');
      this.layer.spec = spec;
      this.buildLayers();
      this.buildForm();
      this.changed();
    } catch (e) {
      this.showError({ error: 'JSON: ' + e.message });
    }
  }

  showError(err) {
    for (const m of this.fields.values()) m.textContent = '';
    this.el.error.textContent = err ? err.error : '';
    if (err && err.param && this.fields.has(err.param)) this.fields.get(err.param).textContent = err.error;
  }

  // ---------- requests ----------
  saveState() {
    const json = JSON.stringify(this.state);
    if (this.options.onState) this.options.onState(json, JSON.stringify(this.layer.spec));
    else history.replaceState(null, '', '#' + encodeURIComponent(json));
  }

  changed() {
    this.el.thetaText.textContent = ` ${this.state.theta_o}°`;
    this.el.phiText.textContent = ` ${this.state.phi_d}°`;
    this.saveState();
    this.refreshPlots();
    this.changedSphere();
    this.refreshVerify();
  }

  changedSphere() {
    this.saveState();
    this.refreshSphereSoon();
  }

  async plotData(spec, kind) {
    // Each view's own arguments only (moving θo does not recompute the slice or the albedo curve, nor φd
    // the others): θo for the polar plot and the 3-D lobe, φd for the slice.
    const own = { polar: ['theta_o'], lobe: ['theta_o'], slice: ['phi_d'], albedo: [] }[kind];
    const params = { spec: JSON.stringify(spec), kind, channel: this.state.channel, ...Object.fromEntries(own.map((k) => [k, this.state[k]])) };
    const key = JSON.stringify(params);
    if (this.cache.has(key)) return this.cache.get(key);
    const r = await this.api('/api/plot', params);
    const body = JSON.parse(text(r.body));
    if (r.status !== 200) throw body;
    if (this.cache.size > 200) this.cache.delete(this.cache.keys().next().value);
    this.cache.set(key, body);
    return body;
  }

  // Each panel is drawn as soon as its numbers arrive (a measured model's albedo takes seconds); the
  // polar, 3-D and slice panels together set dataset.plotToken/plotMs, the albedo albedoToken/albedoMs.
  refreshPlots = debounce(() => {
    const token = ++this.tokens.plots;
    const started = performance.now();
    const shown = this.shown();
    const selected = this.layer;
    const fail = (err) => { if (token === this.tokens.plots) this.showError(err.error ? err : { error: String(err) }); };
    const fetchAll = (kind) => Promise.all(shown.map(({ l }) => this.plotData(l.spec, kind)));
    const panels = [
      fetchAll('polar').then((list) => { if (token === this.tokens.plots) { this.data.polar = { shown, list }; this.drawPolar(); } }),
      fetchAll('lobe').then((list) => { if (token === this.tokens.plots) { this.data.lobe = { shown, list }; this.drawLobe(); } }),
      this.plotData(selected.spec, 'slice').then((d) => { if (token === this.tokens.plots) { this.data.slice = { selected, d }; this.drawSlice(); } }),
    ];
    Promise.all(panels).then(() => {
      if (token !== this.tokens.plots) return;
      this.showError(null);
      this.root.dataset.plotMs = Math.round(performance.now() - started);
      this.root.dataset.plotToken = token;
    }, fail);
    fetchAll('albedo').then((list) => {
      if (token !== this.tokens.plots) return;
      this.data.albedo = { shown, list };
      this.drawAlbedo();
      this.root.dataset.albedoMs = Math.round(performance.now() - started);
      this.root.dataset.albedoToken = token;
    }, fail);
  }, 40);

  refreshSphereSoon = debounce(() => this.refreshSphere(), 40);

  async refreshSphere() {
    const token = ++this.tokens.sphere;
    const st = this.state;
    const base = { spec: JSON.stringify(this.layer.spec), light: st.light, dir: st.dir.join(','), client: this.client, seq: token };
    // Progressive: a small, fast first image, then finer ones, each replacing the last.
    const passes = [{ size: 128, spp: 1 }, { size: 256, spp: 4 }, { size: 256, spp: 16 }, { size: 256, spp: 64 }];
    const started = performance.now();
    for (const [k, pass] of passes.entries()) {
      const r = await this.api('/api/sphere', { ...base, ...pass, seed: k });
      if (token !== this.tokens.sphere) return;
      if (r.status !== 200) {
        if (r.status !== 409) this.el.sphereNote.textContent = JSON.parse(text(r.body)).error;
        return;
      }
      const url = URL.createObjectURL(new Blob([r.body], { type: 'image/png' }));
      const old = this.el.sphere.src;
      this.el.sphere.src = url;
      if (old.startsWith('blob:')) setTimeout(() => URL.revokeObjectURL(old), 1000);
      const ms = Math.round(performance.now() - started);
      if (k === 0) Object.assign(this.root.dataset, { sphereFirstMs: ms, sphereToken: token });
      this.el.sphereNote.textContent = `${pass.size}² px, ${pass.spp} spp, ${ms} ms`;
    }
  }

  refreshVerify = debounce(async () => {
    const token = ++this.tokens.verify;
    this.el.verify.classList.add('gx-busy');
    const r = await this.api('/api/verify', { spec: JSON.stringify(this.layer.spec) });
    if (token !== this.tokens.verify) return;
    this.el.verify.classList.remove('gx-busy');
    const body = JSON.parse(text(r.body));
    if (r.status !== 200) { this.el.verify.textContent = body.error; return; }
    this.el.verify.replaceChildren(
      h('p', { class: body.passed ? 'gx-pass' : 'gx-fail' }, body.passed ? 'every check passed' : 'VIOLATION: a check failed'),
      h('table', {}, body.checks.map((c) => h('tr', { class: c.passed ? 'gx-pass' : 'gx-fail', title: c.detail },
        h('td', {}, c.check), h('td', {}, typeof c.measured === 'number' ? c.measured.toPrecision(4) : c.measured), h('td', {}, c.limit), h('td', {}, c.passed ? 'pass' : 'FAIL')))));
  }, 500);

  async fit() {
    this.el.fitStatus.textContent = ' fitting…';
    const model = this.el.fitModel.value;
    const r = await this.api('/api/fit', { spec: JSON.stringify(this.layer.spec), model });
    const body = JSON.parse(text(r.body));
    if (r.status !== 200) { this.el.fitStatus.textContent = ' ' + body.error; return; }
    this.el.fitStatus.textContent = ` relative error ${body.relative_error.toFixed(4)}`;
    this.addLayer(body.spec, `fit ${model} of ${this.label(this.layer)}`);
  }

  async exportModel(format) {
    const r = await this.api('/api/export', { spec: JSON.stringify(this.layer.spec), format });
    if (r.status !== 200) { this.showError(JSON.parse(text(r.body))); return; }
    download(`${this.layer.spec.type}.${format}`, new Blob([r.body], { type: r.type }));
  }

  exportFigure(name, el, format) {
    if (el.tagName.toLowerCase() === 'canvas') { el.toBlob((b) => download(`${name}.png`, b)); return; }
    const svgText = new XMLSerializer().serializeToString(el);
    if (format === 'svg') { download(`${name}.svg`, new Blob([svgText], { type: 'image/svg+xml' })); return; }
    const img = new Image();
    const [, , w, hgt] = el.getAttribute('viewBox').split(' ').map(Number);
    img.onload = () => {
      const c = h('canvas', { width: 2 * w, height: 2 * hgt });
      const g = c.getContext('2d');
      g.fillStyle = '#fff';
      g.fillRect(0, 0, c.width, c.height);
      g.drawImage(img, 0, 0, c.width, c.height);
      c.toBlob((b) => download(`${name}.png`, b));
    };
    img.src = 'data:image/svg+xml;charset=utf-8,' + encodeURIComponent(svgText);
  }

  // ---------- drawing (numbers from the server only) ----------
  draw() {
    if (this.data.polar) this.drawPolar();
    if (this.data.lobe) this.drawLobe();
    if (this.data.slice) this.drawSlice();
    if (this.data.albedo) this.drawAlbedo();
  }

  radius(v, max) {
    if (v === null || !(v > 0) || !(max > 0)) return 0;
    return this.state.log ? Math.max(0, Math.log10(v / max) + 4) / 4 : v / max;
  }

  drawPolar() {
    const svg = this.el.polar;
    const { shown, list: polar } = this.data.polar;
    // Models that transmit are drawn on the full circle, others on the upper half.
    const full = polar.some((p) => p.transmission);
    const base = full ? 345 : 205;
    const height = base + 14 * shown.length + 4;
    svg.setAttribute('viewBox', `0 0 640 ${height}`);
    svg.replaceChildren(s('rect', { width: 640, height, fill: 'white' }));
    let max = 0;
    for (const p of polar) for (const v of [...p.incidence, ...p.perpendicular]) if (v > max) max = v;
    const R = 145;
    const panels = [['incidence', 'plane of incidence', 160], ['perpendicular', 'perpendicular plane', 480]];
    const to = this.state.theta_o * Math.PI / 180;
    for (const [key, title, cx] of panels) {
      const cy = 175;
      const g = s('g');
      g.append(s('path', { d: full ? `M${cx - R},${cy} a${R},${R} 0 1,1 ${2 * R},0 a${R},${R} 0 1,1 ${-2 * R},0` : `M${cx - R},${cy} A${R},${R} 0 0,1 ${cx + R},${cy} Z`, fill: 'none', stroke: '#bbb' }));
      g.append(s('line', { x1: cx, y1: cy, x2: cx, y2: cy - R, stroke: '#ddd' }));
      if (key === 'incidence') {
        g.append(s('line', { x1: cx, y1: cy, x2: cx + R * Math.sin(to), y2: cy - R * Math.cos(to), stroke: '#888', 'stroke-dasharray': '4 3' }));
        g.append(s('line', { x1: cx, y1: cy, x2: cx - R * Math.sin(to), y2: cy - R * Math.cos(to), stroke: '#ccc', 'stroke-dasharray': '2 3' }));
      }
      polar.forEach((p, k) => {
        const pts = p.angles.map((a, i) => {
          const r = R * this.radius(p[key][i], max);
          const t = a * Math.PI / 180;
          return `${(cx + r * Math.sin(t)).toFixed(2)},${(cy - r * Math.cos(t)).toFixed(2)}`;
        });
        g.append(s('polyline', { points: pts.join(' '), fill: 'none', stroke: shown[k].l.colour, 'stroke-width': 1.6, 'data-layer': shown[k].i }));
      });
      const t = s('text', { x: cx, y: 16, 'text-anchor': 'middle', class: 'gx-label' });
      t.textContent = title + (key === 'incidence' ? ` (viewer at θo = ${this.state.theta_o}°, dashed)` : '');
      g.append(t);
      svg.append(g);
    }
    const scale = s('text', { x: 8, y: base - 6, class: 'gx-label' });
    scale.textContent = this.state.log ? `log scale: 4 decades below the maximum ${max.toPrecision(3)} sr⁻¹` : `max f·cos θi = ${max.toPrecision(3)} sr⁻¹ (${this.state.channel})`;
    svg.append(scale);
    this.legend(svg, shown, 8, base + 10);
  }

  legend(svg, shown, x, y) {
    shown.forEach(({ l }, k) => {
      const yy = y + 14 * k;
      svg.append(s('line', { x1: x, y1: yy - 4, x2: x + 16, y2: yy - 4, stroke: l.colour, 'stroke-width': 2 }));
      const t = s('text', { x: x + 20, y: yy, class: 'gx-label' });
      t.textContent = this.label(l);
      svg.append(t);
    });
  }

  drawLobe() {
    const c = this.el.lobe;
    const g = c.getContext('2d');
    g.fillStyle = '#fff';
    g.fillRect(0, 0, c.width, c.height);
    const { shown, list: lobe } = this.data.lobe;
    let max = 0;
    for (const d of lobe) for (const v of d.values) if (v > max) max = v;
    const { yaw, pitch } = this.view;
    const scale = 150;
    const project = ([x, y, z]) => {
      const x1 = x * Math.cos(yaw) - y * Math.sin(yaw);
      const y1 = x * Math.sin(yaw) + y * Math.cos(yaw);
      const sy = z * Math.cos(pitch) - y1 * Math.sin(pitch);
      return [c.width / 2 + scale * x1, c.height * 0.62 - scale * sy];
    };
    const path = (pts) => { g.beginPath(); pts.forEach((p, i) => { const [u, v] = project(p); if (i) g.lineTo(u, v); else g.moveTo(u, v); }); g.stroke(); };
    g.strokeStyle = '#ccc';
    g.lineWidth = 1;
    path(Array.from({ length: 65 }, (_, i) => [Math.cos(i * Math.PI / 32), Math.sin(i * Math.PI / 32), 0]));
    path([[0, 0, 0], [0, 0, 1]]);
    const to = this.state.theta_o * Math.PI / 180;
    g.strokeStyle = '#888';
    g.setLineDash([4, 3]);
    path([[0, 0, 0], [Math.sin(to), 0, Math.cos(to)]]);
    g.setLineDash([]);
    lobe.forEach((d, k) => {
      g.strokeStyle = shown[k].l.colour;
      g.lineWidth = 0.8;
      const np = d.phi.length;
      const point = (i, j) => {
        const r = this.radius(d.values[i * np + j], max);
        const t = d.theta[i] * Math.PI / 180;
        const p = d.phi[j] * Math.PI / 180;
        return [r * Math.sin(t) * Math.cos(p), r * Math.sin(t) * Math.sin(p), r * Math.cos(t)];
      };
      for (let i = 0; i < d.theta.length; i++) path(Array.from({ length: np + 1 }, (_, j) => point(i, j % np)));
      for (let j = 0; j < np; j += 3) path(d.theta.map((_, i) => point(i, j)));
    });
  }

  dragLobe() {
    const c = this.el.lobe;
    let last = null;
    c.addEventListener('pointerdown', (e) => { last = [e.clientX, e.clientY]; c.setPointerCapture(e.pointerId); });
    c.addEventListener('pointermove', (e) => {
      if (!last) return;
      this.view.yaw += (e.clientX - last[0]) * 0.01;
      this.view.pitch = Math.max(-1.5, Math.min(1.5, this.view.pitch + (e.clientY - last[1]) * 0.01));
      last = [e.clientX, e.clientY];
      if (this.data.lobe) this.drawLobe();
    });
    c.addEventListener('pointerup', () => { last = null; });
  }

  dragLight() {
    const img = this.el.sphere;
    let down = false;
    const set = (e) => {
      const rect = img.getBoundingClientRect();
      // The sphere fills 90 % of the frame (gonio::preview): a point on it is the normal there.
      let x = ((e.clientX - rect.left) / rect.width * 2 - 1) / 0.9;
      let y = -((e.clientY - rect.top) / rect.height * 2 - 1) / 0.9;
      const r2 = x * x + y * y;
      if (r2 > 1) { x /= Math.sqrt(r2); y /= Math.sqrt(r2); }
      const z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
      this.state.dir = [x, y, z].map((v) => +v.toFixed(3));
      this.state.light = 'dir';
      this.el.light.value = 'dir';
      this.changedSphere();
    };
    img.addEventListener('pointerdown', (e) => { down = true; img.setPointerCapture(e.pointerId); set(e); });
    img.addEventListener('pointermove', (e) => { if (down) set(e); });
    img.addEventListener('pointerup', () => { down = false; });
  }

  drawSlice() {
    const c = this.el.slice;
    const g = c.getContext('2d');
    g.fillStyle = '#fff';
    g.fillRect(0, 0, c.width, c.height);
    const { d, selected } = this.data.slice;
    const nh = d.theta_h.length;
    const nd = d.theta_d.length;
    let max = 0;
    for (const v of d.values) if (v > max) max = v;
    const img = g.createImageData(nh, nd);
    for (let j = 0; j < nd; j++) {
      for (let i = 0; i < nh; i++) {
        const v = d.values[j * nh + i];
        // Rows from θd = 90° at the top to 0° at the bottom; log of the value over 4 decades.
        const o = 4 * ((nd - 1 - j) * nh + i);
        if (v === null) { img.data.set([200, 200, 200, 255], o); continue; }
        const t = v > 0 && max > 0 ? Math.max(0, Math.log10(v / max) + 4) / 4 : 0;
        img.data.set([...heat(t), 255], o);
      }
    }
    const tmp = h('canvas', { width: nh, height: nd });
    tmp.getContext('2d').putImageData(img, 0, 0);
    g.imageSmoothingEnabled = false;
    g.drawImage(tmp, 40, 10, 280, 280);
    g.fillStyle = '#333';
    g.font = '12px sans-serif';
    g.fillText('θh → (0° … 90°, MERL\'s square-root spacing)', 40, 310);
    g.save();
    g.translate(28, 290);
    g.rotate(-Math.PI / 2);
    g.fillText('θd → (0° … 90°)', 0, 0);
    g.restore();
    g.fillText(`${this.label(selected)}`, 330, 24);
    g.fillText(`max ${max.toPrecision(3)} sr⁻¹`, 330, 42);
    g.fillText('log, 4 decades', 330, 60);
    g.fillText(`φd = ${d.phi_d}°`, 330, 78);
    for (let k = 0; k <= 10; k++) { g.fillStyle = `rgb(${heat(k / 10).join(',')})`; g.fillRect(330, 280 - k * 20, 16, 20); }
  }

  drawAlbedo() {
    const svg = this.el.albedo;
    svg.replaceChildren(s('rect', { width: 420, height: 300, fill: 'white' }));
    const { shown, list: albedo } = this.data.albedo;
    let max = 1.05;
    for (const a of albedo) for (const v of a.albedo) if (v > max) max = v * 1.05;
    const X = (t) => 50 + (t / 90) * 340;
    const Y = (v) => 260 - (v / max) * 230;
    svg.append(s('path', { d: `M50,30 V260 H390`, fill: 'none', stroke: '#999' }));
    svg.append(s('line', { x1: 50, x2: 390, y1: Y(1), y2: Y(1), stroke: '#aaa', 'stroke-dasharray': '4 3' }));
    svg.append(s('line', { x1: X(this.state.theta_o), x2: X(this.state.theta_o), y1: 30, y2: 260, stroke: '#ddd' }));
    for (const t of [0, 30, 60, 90]) { const e = s('text', { x: X(t), y: 276, 'text-anchor': 'middle', class: 'gx-label' }); e.textContent = `${t}°`; svg.append(e); }
    for (const v of [0, 0.5, 1]) { const e = s('text', { x: 44, y: Y(v) + 4, 'text-anchor': 'end', class: 'gx-label' }); e.textContent = v; svg.append(e); }
    const xl = s('text', { x: 220, y: 294, 'text-anchor': 'middle', class: 'gx-label' });
    xl.textContent = 'θo';
    svg.append(xl);
    albedo.forEach((a, k) => {
      const pts = a.theta_o.map((t, i) => `${X(t).toFixed(2)},${Y(a.albedo[i] ?? 0).toFixed(2)}`).join(' ');
      svg.append(s('polyline', { points: pts, fill: 'none', stroke: shown[k].l.colour, 'stroke-width': 1.8 }));
      const e = s('text', { x: 60, y: 44 + 14 * k, class: 'gx-label', fill: shown[k].l.colour });
      e.textContent = `${this.label(shown[k].l)}: white furnace ${a.furnace_channel === null ? '—' : a.furnace_channel.toFixed(4)}`;
      svg.append(e);
    });
  }
}

/** Slider position 0…1000 to a value and back: linear, or logarithmic over ranges of many decades. */
function sliderScale(lo, hi, integer) {
  const round = (v) => (integer ? Math.round(v) : +v.toPrecision(4));
  if (lo > 0 && hi / lo >= 100) {
    const a = Math.log(lo);
    const b = Math.log(hi);
    return { fromSlider: (t) => round(Math.exp(a + (b - a) * t / 1000)), toSlider: (v) => Math.round(1000 * (Math.log(Math.max(v, lo)) - a) / (b - a)) };
  }
  if (lo >= 0 && hi >= 1000) {
    const b = Math.log1p(hi - lo);
    return { fromSlider: (t) => round(lo + Math.expm1(b * t / 1000)), toSlider: (v) => Math.round(1000 * Math.log1p(Math.max(0, v - lo)) / b) };
  }
  return { fromSlider: (t) => round(lo + (hi - lo) * t / 1000), toSlider: (v) => Math.round(1000 * (v - lo) / (hi - lo)) };
}

function parseNumbers(t) {
  const parts = t.split(',').map((x) => x.trim()).filter((x) => x !== '');
  const nums = parts.map(Number);
  if (parts.length === 1) return Number.isNaN(nums[0]) ? parts[0] : nums[0];
  return nums;
}
const toHex = (rgb) => '#' + rgb.map((v) => Math.round(255 * Math.min(1, Math.max(0, +v || 0))).toString(16).padStart(2, '0')).join('');
const fromHex = (hex) => [1, 3, 5].map((k) => +(parseInt(hex.slice(k, k + 2), 16) / 255).toFixed(4));

/** A perceptual-ish heat map: black, purple, orange, yellow, white. */
function heat(t) {
  const stops = [[0, 0, 0], [80, 18, 123], [182, 54, 121], [251, 136, 97], [252, 253, 191]];
  const x = Math.min(1, Math.max(0, t)) * (stops.length - 1);
  const k = Math.min(stops.length - 2, Math.floor(x));
  const f = x - k;
  return stops[k].map((v, i) => Math.round(v + (stops[k + 1][i] - v) * f));
}

/** The anywidget entry point: the same explorer, talking to Python through widget messages. */
export default {
  render({ model, el }) {
    const style = model.get('_css_text');
    if (style) el.append(Object.assign(document.createElement('style'), { textContent: style }));
    const root = document.createElement('div');
    el.append(root);
    mount(root, widgetTransport(model), {
      state: model.get('state') || null,
      onState: (state, spec) => { model.set('state', state); model.set('spec', spec); model.save_changes(); },
    });
  },
};
