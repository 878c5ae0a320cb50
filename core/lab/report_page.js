/* report_page.js — the comparison page's behaviour (`murk compare --html`, `murk bench`'s report.html).
 *
 * The data (the JSON in #murk-data, written by core/lab/report_html.c): every image as linear half floats
 * (IEEE binary16, little endian, base64, in the element named by its id) times 2^exp, and for the variants
 * their per-pixel error maps (the channel mean of the relative squared error against the reference; for a
 * bench the mean over its seeds).
 * Tone mapping is murk's PNG preview's: x = linear * 2^EV, clamped to [0, 1], sRGB transfer curve, 8 bits
 * (round half up), computed from the half floats themselves, so any exposure is exact. NaN is magenta and
 * an infinity cyan, in every view; the readout names them.
 *
 * Maps, each on a fixed scale (the legend states it):
 *   relative error    |a - r| / (|r| + 0.01), mean of R, G, B; log scale 10^-3 .. 10^1 (black .. yellow)
 *   signed difference (a - r) / (|r| + 0.01), mean of R, G, B; blue -S .. white 0 .. red +S (S = 0.1, 1, 10;
 *                     murk compare --diff's signed map with --scale S)
 *   efficiency        1 / (e(p) * cost) over the first variant's whole-image 1 / (relMSE * cost), e(p) the
 *                     7 x 7-pixel mean of the error map (the part inside the image at the edges), cost the
 *                     mean seconds or density lookups of a render; log scale 0.1x .. 10x (purple .. green)
 *   most efficient    the variant of the largest efficiency per pixel (as tools/bench_report.py's chart)
 * window.murkPage gives tests the view's geometry (imageToCanvas) and state; people use the controls. */
'use strict';
(function () {
  const D = JSON.parse(document.getElementById('murk-data').textContent);
  const W = D.width, H = D.height, NPIX = W * H;
  const $ = (id) => document.getElementById(id);
  const el = (tag, attrs, ...kids) => {
    const e = document.createElement(tag);
    for (const k in attrs || {}) {
      if (k === 'class') e.className = attrs[k];
      else if (k === 'text') e.textContent = attrs[k];
      else e.setAttribute(k, attrs[k]);
    }
    for (const c of kids) e.append(c);
    return e;
  };
  const NAN_RGB = [255, 0, 255], INF_RGB = [0, 255, 255], NONE_RGB = [64, 64, 64], FLAT_RGB = [128, 128, 128];

  /* ---- half floats ---- */
  const HALF = new Float32Array(65536);
  for (let h = 0; h < 65536; h++) {
    const e = (h >> 10) & 31, m = h & 1023, s = h & 0x8000 ? -1 : 1;
    HALF[h] = e === 31 ? (m ? NaN : s * Infinity) : e ? s * (1024 + m) * 2 ** (e - 25) : s * m * 2 ** -24;
  }
  const LITTLE = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
  function decode(a) { /* the halves of element a.id: base64 of little-endian bytes */
    const e = document.getElementById(a.id), text = e.textContent;
    e.remove(); /* its text is not needed again */
    if (Uint8Array.fromBase64 && LITTLE) {
      const b = Uint8Array.fromBase64(text);
      return new Uint16Array(b.buffer, 0, b.length >> 1);
    }
    const bin = atob(text), n = bin.length >> 1, u = new Uint16Array(n);
    for (let i = 0, j = 0; i < n; i++, j += 2) u[i] = bin.charCodeAt(j) | (bin.charCodeAt(j + 1) << 8);
    return u;
  }

  const IM = D.images.map((d, i) => {
    const im = { index: i, label: d.label, note: d.note, reference: d.reference, seconds: d.seconds,
      lookups: d.lookups, relmse: d.relmse, bits: decode(d.rgb), exp: d.rgb.exp, err: null, maps: {},
      nan: 0, inf: 0 };
    if (d.err) {
      const b = decode(d.err), sc = 2 ** d.err.exp;
      im.err = new Float32Array(b.length);
      for (let k = 0; k < b.length; k++) im.err[k] = HALF[b[k]] * sc;
    }
    for (let p = 0; p < NPIX; p++) { /* pixels with a NaN, else an infinity, in some channel */
      let nan = false, inf = false;
      for (let c = 0; c < 3; c++) {
        const h = im.bits[3 * p + c];
        if ((h & 0x7c00) === 0x7c00) { if (h & 0x3ff) nan = true; else inf = true; }
      }
      if (nan) im.nan++; else if (inf) im.inf++;
    }
    return im;
  });
  const REF = Math.max(0, IM.findIndex((im) => im.reference));
  const WITH_ERR = IM.filter((im) => im.err);
  const FIRST = WITH_ERR.length ? WITH_ERR[0] : null; /* the first variant: the efficiency maps' unit */

  /* ---- number formatting ---- */
  function fv(v) {
    if (v !== v) return 'NaN';
    if (v === Infinity) return '+Inf';
    if (v === -Infinity) return '-Inf';
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : v.toPrecision(4);
  }
  function g3(x) { /* C's %.3g, near enough */
    if (!(x === x)) return 'n/a';
    const a = Math.abs(x);
    return a !== 0 && (a < 1e-4 || a >= 1e6) ? x.toExponential(2) : String(Number(x.toPrecision(3)));
  }
  const pm = (m, s) => (m === m ? (s === s ? g3(m) + ' \u00b1 ' + Number(s.toPrecision(2)) : g3(m)) : 'n/a');
  const mib = (b) => (b < 1048576 ? (b / 1024).toFixed(1) + ' KiB' : (b / 1048576).toFixed(1) + ' MiB');

  /* ---- colours ---- */
  function srgb8(x) { /* murk's PNG preview (core/image/png.c) */
    if (!(x > 0)) x = 0;
    if (x > 1) x = 1;
    x = x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
    return Math.floor(x * 255 + 0.5);
  }
  const lutCache = new Map();
  function toneLut(mult) { /* half bits -> 0..255, 256 for NaN, 257 for an infinity */
    let l = lutCache.get(mult);
    if (l) return l;
    l = new Uint16Array(65536);
    for (let h = 0; h < 65536; h++) {
      const v = HALF[h];
      l[h] = v !== v ? 256 : v === Infinity || v === -Infinity ? 257 : srgb8(v * mult);
    }
    if (lutCache.size > 8) lutCache.clear();
    lutCache.set(mult, l);
    return l;
  }
  const ramp = (stops) => (t) => { /* piecewise linear through evenly spaced stops, t in [0, 1] */
    const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1), i = Math.min(Math.floor(x), stops.length - 2);
    const f = x - i, a = stops[i], b = stops[i + 1];
    return [0, 1, 2].map((c) => Math.round(a[c] + (b[c] - a[c]) * f));
  };
  const INFERNO = ramp([[0, 0, 4], [40, 11, 84], [101, 21, 110], [159, 42, 99], [212, 72, 66], [245, 125, 21],
    [250, 193, 39], [252, 255, 164]]);
  const BWR = ramp([[0, 0, 255], [255, 255, 255], [255, 0, 0]]); /* murk compare's signed map */
  const PRGN = ramp([[64, 0, 75], [153, 112, 171], [247, 247, 247], [90, 174, 97], [0, 68, 27]]);
  const TAB10 = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40], [148, 103, 189], [140, 86, 75],
    [227, 119, 194], [127, 127, 127], [188, 189, 34], [23, 190, 207]];
  const MODES = {
    relerr: { ramp: INFERNO, lo: -3, hi: 1, log: true,
      ticks: [[0, '0.001'], [0.25, '0.01'], [0.5, '0.1'], [0.75, '1'], [1, '10']],
      text: () => 'relative error |a \u2212 r| / (|r| + 0.01), mean of R, G, B, against the reference; fixed log ' +
        'scale 10^\u22123 (black) to 10^1 (yellow). NaN magenta, \u00b1Inf cyan.' },
    signed: { ramp: BWR, log: false,
      ticks: () => [[0, '\u2212' + S.signed], [0.5, '0'], [1, '+' + S.signed]],
      text: () => 'signed difference (a \u2212 r) / (|r| + 0.01), mean of R, G, B; fixed scale: blue \u2212' +
        S.signed + ', white 0, red +' + S.signed + ' (murk compare --diff --scale ' + S.signed + '). NaN magenta, ' +
        '\u00b1Inf cyan.' },
    efficiency: { ramp: PRGN, lo: -1, hi: 1, log: true,
      ticks: [[0, '0.1\u00d7'], [0.25, '0.32\u00d7'], [0.5, '1\u00d7'], [0.75, '3.2\u00d7'], [1, '10\u00d7']],
      text: () => 'efficiency per pixel, 1 / (e \u00b7 ' + costName() + '), relative to the first variant\u2019s ' +
        'whole-image efficiency (\'' + (FIRST ? FIRST.label : '?') + '\'); e = the 7\u00d77-pixel mean of the ' +
        'per-pixel relative squared error' + (D.kind === 'bench' ? ' (mean over the seeds)' : '') + '; fixed log ' +
        'scale 0.1\u00d7 (purple) to 10\u00d7 (green); grey: no error around the pixel, dark grey: no error map (the ' +
        'reference).' + (costKnown() ? '' : ' The cost is unknown: equal cost.') },
  };

  /* ---- state ---- */
  const S = { cur: 0, mode: 'image', ev: 0, split: false, other: REF === 0 && IM.length > 1 ? 1 : REF,
    divider: 0.5, zoom: 1, ox: 0, oy: 0, signed: 1, cost: 'seconds' };
  const costName = () => (S.cost === 'lookups' ? 'density lookups' : 'seconds');
  const costOf = (im) => (S.cost === 'lookups' ? im.lookups : im.seconds);
  const costKnown = () => WITH_ERR.every((im) => costOf(im) > 0);

  /* ---- maps ---- */
  function linear(im) {
    if (!im.lin) {
      const s = 2 ** im.exp;
      im.lin = new Float32Array(im.bits.length);
      for (let k = 0; k < im.bits.length; k++) im.lin[k] = HALF[im.bits[k]] * s;
    }
    return im.lin;
  }
  function diffMap(im, signed) {
    const key = signed ? 'signed' : 'relerr';
    if (!im.maps[key]) {
      const a = linear(im), r = linear(IM[REF]), m = new Float32Array(NPIX);
      for (let p = 0; p < NPIX; p++) {
        let s = 0;
        for (let c = 3 * p; c < 3 * p + 3; c++) {
          const d = (a[c] - r[c]) / (Math.abs(r[c]) + 0.01);
          s += signed ? d : Math.abs(d);
        }
        m[p] = s / 3;
      }
      im.maps[key] = m;
    }
    return im.maps[key];
  }
  function blurred(im) { /* 7x7 box mean of the error map (NaN as 0), the part inside the image */
    if (!im.maps.blur) {
      const R = 3, I = new Float64Array((W + 1) * (H + 1)), m = new Float32Array(NPIX);
      for (let y = 0; y < H; y++)
        for (let x = 0, row = 0; x < W; x++) {
          const v = im.err[y * W + x];
          row += v === v ? v : 0;
          I[(y + 1) * (W + 1) + x + 1] = I[y * (W + 1) + x + 1] + row;
        }
      for (let y = 0; y < H; y++)
        for (let x = 0; x < W; x++) {
          const x0 = Math.max(x - R, 0), x1 = Math.min(x + R + 1, W);
          const y0 = Math.max(y - R, 0), y1 = Math.min(y + R + 1, H);
          const s = I[y1 * (W + 1) + x1] - I[y0 * (W + 1) + x1] - I[y1 * (W + 1) + x0] + I[y0 * (W + 1) + x0];
          m[y * W + x] = s / ((x1 - x0) * (y1 - y0));
        }
      im.maps.blur = m;
    }
    return im.maps.blur;
  }
  function firstMean() {
    if (FIRST.meanErr === undefined) {
      let s = 0, n = 0;
      for (const v of FIRST.err) if (v === v) { s += v; n++; }
      FIRST.meanErr = n ? s / n : NaN;
    }
    return FIRST.meanErr;
  }
  const cost = (im) => (costKnown() ? costOf(im) : 1);
  function effMap(im) { /* efficiency over the first variant's whole-image efficiency; NaN where the error is
                           NaN, -1 where there is no error (around the pixel) */
    const key = 'eff-' + S.cost;
    if (!im.maps[key]) {
      const b = blurred(im), unit = Math.max(firstMean(), 1e-12) * cost(FIRST) / cost(im), m = new Float32Array(NPIX);
      for (let p = 0; p < NPIX; p++) m[p] = im.err[p] !== im.err[p] ? NaN : b[p] > 1e-12 ? unit / b[p] : -1;
      im.maps[key] = m;
    }
    return im.maps[key];
  }
  function winnerMap() { /* index into WITH_ERR, -1 where no variant has any error */
    const key = 'win-' + S.cost;
    if (!IM[0].maps[key]) {
      const m = new Int16Array(NPIX).fill(-1), best = new Float64Array(NPIX).fill(Infinity);
      const shares = new Float64Array(WITH_ERR.length);
      WITH_ERR.forEach((im, v) => {
        const b = blurred(im), c = cost(im);
        for (let p = 0; p < NPIX; p++) {
          const e = b[p] * c;
          if (b[p] > 1e-12 && e < best[p]) { best[p] = e; m[p] = v; }
        }
      });
      for (let p = 0; p < NPIX; p++) if (m[p] >= 0) shares[m[p]]++;
      IM[0].maps[key] = { m, shares: Array.from(shares, (s) => s / NPIX) };
    }
    return IM[0].maps[key];
  }

  /* ---- painting a layer (one image in the current mode) into RGBA ---- */
  function put(d, q, c) { d[q] = c[0]; d[q + 1] = c[1]; d[q + 2] = c[2]; d[q + 3] = 255; }
  function paintImage(im, d) {
    const lut = toneLut(2 ** (S.ev + im.exp)), b = im.bits;
    for (let p = 0, q = 0, k = 0; p < NPIX; p++, q += 4, k += 3) {
      const r = lut[b[k]], g = lut[b[k + 1]], bl = lut[b[k + 2]];
      if ((r | g | bl) & 256) put(d, q, r === 256 || g === 256 || bl === 256 ? NAN_RGB : INF_RGB);
      else { d[q] = r; d[q + 1] = g; d[q + 2] = bl; d[q + 3] = 255; }
    }
  }
  function paintValues(m, mode, d) {
    const pal = [], N = 1024;
    for (let i = 0; i <= N; i++) pal.push(mode.ramp(i / N));
    for (let p = 0, q = 0; p < NPIX; p++, q += 4) {
      const v = m[p];
      if (v !== v) { put(d, q, NAN_RGB); continue; }
      if (v === Infinity || v === -Infinity) { put(d, q, INF_RGB); continue; }
      if (mode === MODES.efficiency && v < 0) { put(d, q, FLAT_RGB); continue; }
      const t = mode.log ? (Math.log10(Math.max(v, 1e-30)) - mode.lo) / (mode.hi - mode.lo) : 0.5 + 0.5 * v / S.signed;
      put(d, q, pal[Math.round(Math.min(Math.max(t, 0), 1) * N)]);
    }
  }
  function paint(im, d) {
    if (S.mode === 'image') return paintImage(im, d);
    if (S.mode === 'relerr' || S.mode === 'signed')
      return paintValues(diffMap(im, S.mode === 'signed'), MODES[S.mode], d);
    if (S.mode === 'efficiency') {
      if (!im.err) { for (let q = 0; q < 4 * NPIX; q += 4) put(d, q, NONE_RGB); return; }
      return paintValues(effMap(im), MODES.efficiency, d);
    }
    const w = winnerMap().m; /* winner */
    for (let p = 0, q = 0; p < NPIX; p++, q += 4) put(d, q, w[p] < 0 ? FLAT_RGB : TAB10[w[p] % 10]);
  }

  /* ---- the view ---- */
  const canvas = $('view'), ctx = canvas.getContext('2d');
  const layers = [0, 1].map(() => {
    const c = document.createElement('canvas');
    c.width = W;
    c.height = H;
    return { canvas: c, ctx: c.getContext('2d'), data: new ImageData(W, H), key: '' };
  });
  function layer(k, i) {
    const L = layers[k], key = [S.mode, i, S.ev, S.signed, S.cost].join('|');
    if (L.key !== key) {
      paint(IM[i], L.data.data);
      L.ctx.putImageData(L.data, 0, 0);
      L.key = key;
    }
    return L.canvas;
  }
  const dpr = () => window.devicePixelRatio || 1;
  const dividerX = () => Math.round(S.divider * canvas.width);
  function draw() {
    const cw = canvas.width, ch = canvas.height;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = '#1c1c1c';
    ctx.fillRect(0, 0, cw, ch);
    ctx.imageSmoothingEnabled = false;
    const sides = S.split ? [[S.cur, 0, dividerX()], [S.other, dividerX(), cw]] : [[S.cur, 0, cw]];
    sides.forEach(([i, x0, x1], k) => {
      const src = layer(k, i);
      ctx.save();
      ctx.beginPath();
      ctx.rect(x0, 0, x1 - x0, ch);
      ctx.clip();
      ctx.setTransform(S.zoom, 0, 0, S.zoom, S.ox, S.oy);
      ctx.drawImage(src, 0, 0);
      ctx.restore();
    });
    if (S.split) {
      ctx.fillStyle = '#f0a030';
      ctx.fillRect(dividerX() - 1, 0, 2, ch);
    }
    $('split-labels').hidden = !S.split;
    if (S.split) {
      $('split-left').textContent = '\u2190 ' + keyName(S.cur) + ' ' + IM[S.cur].label;
      $('split-right').textContent = keyName(S.other) + ' ' + IM[S.other].label + ' \u2192';
    }
  }
  function fit() {
    const cw = canvas.width, ch = canvas.height;
    let z = Math.min(cw / W, ch / H);
    if (z >= 1) z = Math.floor(z);
    S.zoom = z;
    S.ox = Math.round((cw - W * z) / 2);
    S.oy = Math.round((ch - H * z) / 2);
  }
  function zoomAt(f, cx, cy) {
    const z = Math.min(Math.max(S.zoom * f, 1 / 64), 256);
    S.ox = cx - (cx - S.ox) * (z / S.zoom);
    S.oy = cy - (cy - S.oy) * (z / S.zoom);
    S.zoom = z;
  }
  function resize() {
    /* the image as wide as the page, but short enough that the controls, legend and readout stay in view */
    const cssW = $('stage').clientWidth;
    const cssH = Math.round(Math.max(240, Math.min(window.innerHeight * 0.62, cssW * H / W)));
    canvas.style.height = cssH + 'px';
    canvas.width = Math.round(cssW * dpr());
    canvas.height = Math.round(cssH * dpr());
    fit();
  }

  /* ---- controls ---- */
  const keyName = (i) => (i < 9 ? String(i + 1) : '') + (IM[i].reference ? (i < 9 ? '/r' : 'r') : '');
  function update() {
    document.querySelectorAll('#images button').forEach((b, i) => b.classList.toggle('active', i === S.cur));
    document.querySelectorAll('#modes button').forEach((b) => b.classList.toggle('active', b.dataset.mode === S.mode));
    $('exposure').value = S.ev;
    $('exposure-value').textContent = (S.ev >= 0 ? '+' : '') + S.ev.toFixed(1) + ' EV';
    $('split-on').checked = S.split;
    $('split-other').value = String(S.other);
    $('split').value = S.divider;
    $('scale-label').hidden = S.mode !== 'signed';
    $('cost-label').hidden = !(S.mode === 'efficiency' || S.mode === 'winner') || !IM.some((im) => im.lookups > 0);
    legend();
    draw();
    readout();
  }
  function legend() {
    const bar = $('legend-bar'), ticks = $('legend-ticks'), text = $('legend-text');
    const tick = ([t, s]) => ticks.append(el('span', { text: s, style: 'left:' + 100 * t + '%' }));
    ticks.textContent = '';
    if (S.mode === 'image') {
      bar.style.background = 'linear-gradient(to right, #000, #fff)';
      [[0, '0'], [1, fv(2 ** -S.ev) + ' and above']].forEach(tick);
      text.textContent = 'linear \u00d7 2^' + S.ev.toFixed(1) + ', clamped to [0, 1], sRGB (as murk\u2019s PNG ' +
        'preview); NaN magenta, \u00b1Inf cyan.';
      return;
    }
    if (S.mode === 'winner') {
      bar.style.background = 'none';
      text.textContent = 'most efficient variant per pixel (' + costName() + ', 7\u00d77-pixel mean error):';
      const w = winnerMap();
      WITH_ERR.forEach((im, v) => {
        const c = TAB10[v % 10];
        text.append(el('span', { class: 'swatch', style: 'background:rgb(' + c.join(',') + ')' }),
          im.label + ' ' + (100 * w.shares[v]).toFixed(0) + '%');
      });
      return;
    }
    const m = MODES[S.mode], stops = [];
    for (let i = 0; i <= 8; i++) stops.push('rgb(' + m.ramp(i / 8).join(',') + ') ' + (100 * i / 8) + '%');
    bar.style.background = 'linear-gradient(to right, ' + stops.join(', ') + ')';
    (typeof m.ticks === 'function' ? m.ticks() : m.ticks).forEach(tick);
    text.textContent = m.text();
  }
  function select(i) {
    if (i < 0 || i >= IM.length) return;
    if (S.split && i === S.other) S.other = S.cur;
    S.cur = i;
    update();
  }
  function setMode(m) {
    if (!modeAvailable(m)) return;
    S.mode = m;
    update();
  }
  const modeAvailable = (m) => m === 'image' || m === 'relerr' || m === 'signed' ||
    (m === 'efficiency' && WITH_ERR.length > 0) || (m === 'winner' && WITH_ERR.length > 1);
  function setEv(v) {
    S.ev = Math.round(Math.min(Math.max(v, -10), 10) * 10) / 10;
    update();
  }

  /* ---- the readout ---- */
  let pointer = null; /* the last pointer position, canvas pixels */
  function pixelAt(cx, cy) { return [Math.floor((cx - S.ox) / S.zoom), Math.floor((cy - S.oy) / S.zoom)]; }
  function rgbText(im, p) {
    const s = 2 ** im.exp;
    return ['R', 'G', 'B'].map((n, c) => n + ' ' + fv(HALF[im.bits[3 * p + c]] * s).padEnd(10)).join(' ');
  }
  function mapText(im, p) {
    if (S.mode === 'relerr' || S.mode === 'signed')
      return (S.mode === 'signed' ? 'signed difference ' : 'relative error ') + fv(diffMap(im, S.mode === 'signed')[p]);
    if (S.mode === 'efficiency')
      return !im.err ? 'no error map (the reference)' : effMap(im)[p] < 0 ? 'no error around this pixel' :
        'efficiency ' + fv(effMap(im)[p]) + '\u00d7 the first variant\u2019s whole-image efficiency' +
        ' (error here ' + fv(im.err[p]) + ', 7\u00d77 mean ' + fv(blurred(im)[p]) + ')';
    if (S.mode === 'winner') {
      const v = winnerMap().m[p];
      return 'most efficient here: ' + (v < 0 ? 'none (no error in any variant)' : WITH_ERR[v].label);
    }
    return '';
  }
  function readout() {
    const out = $('readout');
    if (!pointer) return;
    const [x, y] = pixelAt(pointer[0], pointer[1]);
    if (x < 0 || y < 0 || x >= W || y >= H) { out.textContent = 'outside the image'; return; }
    const p = y * W + x, side = S.split && pointer[0] >= dividerX() ? S.other : S.cur, k = D.factor;
    const lines = ['pixel x ' + x + ', y ' + y + (k > 1 ? '   (the renders\u2019 x ' + x * k + '\u2013' +
      (Math.min((x + 1) * k, D.source[0]) - 1) + ', y ' + y * k + '\u2013' + (Math.min((y + 1) * k, D.source[1]) - 1) +
      ': their mean)' : '')];
    const shown = [side];
    if (S.split) shown.push(side === S.cur ? S.other : S.cur);
    if (!shown.includes(REF)) shown.push(REF);
    const width = Math.max(...shown.map((i) => IM[i].label.length), 9);
    shown.forEach((i, n) => lines.push((n ? '  ' : '\u25b8 ') + IM[i].label.padEnd(width) + '  ' + rgbText(IM[i], p)));
    const mt = mapText(IM[side], p);
    if (mt) lines.push('  ' + mt);
    out.textContent = lines.join('\n');
  }

  /* ---- building the page ---- */
  function buildControls() {
    IM.forEach((im, i) => {
      const b = el('button', { type: 'button', title: im.note || im.label });
      const k = keyName(i);
      if (k) b.append(el('span', { class: 'key', text: k }));
      b.append(im.label);
      if (im.note) b.append(el('span', { class: 'sub', text: im.note }));
      b.addEventListener('click', () => select(i));
      $('images').append(b);
      $('split-other').append(el('option', { value: String(i), text: (k ? k + ' ' : '') + im.label }));
    });
    document.querySelectorAll('#modes button').forEach((b) => {
      b.disabled = !modeAvailable(b.dataset.mode);
      b.addEventListener('click', () => setMode(b.dataset.mode));
    });
    $('exposure').addEventListener('input', (e) => setEv(parseFloat(e.target.value)));
    $('split-on').addEventListener('change', (e) => { S.split = e.target.checked; update(); });
    $('split-other').addEventListener('change', (e) => { S.other = parseInt(e.target.value, 10); update(); });
    $('split').addEventListener('input', (e) => { S.divider = parseFloat(e.target.value); update(); });
    $('signed-scale').addEventListener('change', (e) => { S.signed = parseFloat(e.target.value); update(); });
    $('cost').addEventListener('change', (e) => { S.cost = e.target.value; update(); });
    $('fit').addEventListener('click', () => { fit(); update(); });
    $('one').addEventListener('click', () => { oneToOne(); update(); });
    $('stage').append(el('div', { id: 'split-labels', hidden: '' }, el('span', { id: 'split-left' }),
      el('span', { id: 'split-right' })));
  }
  function oneToOne() {
    const cx = canvas.width / 2, cy = canvas.height / 2;
    zoomAt(dpr() / S.zoom, cx, cy);
  }
  function bindView() {
    let drag = null;
    const pos = (e) => [e.offsetX * dpr(), e.offsetY * dpr()];
    canvas.addEventListener('mousedown', (e) => {
      const [cx, cy] = pos(e);
      const onDivider = S.split && Math.abs(cx - dividerX()) <= 6 * dpr();
      drag = onDivider ? { divider: true } : { x: cx, y: cy, ox: S.ox, oy: S.oy };
      canvas.focus();
      e.preventDefault();
    });
    window.addEventListener('mouseup', () => { drag = null; });
    canvas.addEventListener('mousemove', (e) => {
      pointer = pos(e);
      if (drag && drag.divider) {
        S.divider = Math.min(Math.max(pointer[0] / canvas.width, 0), 1);
        update();
      } else if (drag) {
        S.ox = drag.ox + pointer[0] - drag.x;
        S.oy = drag.oy + pointer[1] - drag.y;
        draw();
      }
      readout();
    });
    canvas.addEventListener('mouseleave', () => { pointer = null; });
    canvas.addEventListener('wheel', (e) => {
      const [cx, cy] = pos(e);
      zoomAt(e.deltaY < 0 ? 1.25 : 0.8, cx, cy);
      draw();
      readout();
      e.preventDefault();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { fit(); draw(); readout(); });
    document.addEventListener('keydown', (e) => {
      if (e.ctrlKey || e.metaKey || e.altKey || (e.target && /^(TEXTAREA|SELECT)$/.test(e.target.tagName))) return;
      const k = e.key;
      if (k >= '1' && k <= '9') select(parseInt(k, 10) - 1);
      else if (k === '0' || k === 'r') select(REF);
      else if (k === 'i') setMode('image');
      else if (k === 'e') setMode('relerr');
      else if (k === 'd') setMode('signed');
      else if (k === 'f') setMode('efficiency');
      else if (k === 'w') setMode('winner');
      else if (k === 's') { S.split = !S.split && IM.length > 1; update(); }
      else if (k === 'x' && S.split) { [S.cur, S.other] = [S.other, S.cur]; update(); }
      else if (k === '+' || k === '=') setEv(S.ev + 0.5);
      else if (k === '-' || k === '_') setEv(S.ev - 0.5);
      else if (k === 'z') { fit(); update(); }
      else if (k === 'a') { oneToOne(); update(); }
      else return;
      e.preventDefault();
    });
    window.addEventListener('resize', () => { resize(); update(); });
  }
  function notices() {
    const box = $('notices'), say = (t) => box.append(el('div', { class: 'notice', text: t }));
    if (D.factor > 1)
      say('Downsampled: these images are ' + D.factor + '\u00d7 smaller than the renders (' + D.source[0] + '\u00d7' +
        D.source[1] + ' \u2192 ' + W + '\u00d7' + H + '; each pixel the mean of ' + D.factor + '\u00d7' + D.factor +
        ' pixels, maps too) to keep the page\u2019s image data within its limit of ' + mib(D.limit) +
        ' (MURK_MAX_PAGE_BYTES raises it).');
    const count = (n, what) => n + ' ' + what + (n > 1 ? 's' : '');
    IM.forEach((im) => {
      const parts = [];
      if (im.nan) parts.push(count(im.nan, 'NaN pixel') + ' (magenta)');
      if (im.inf) parts.push(count(im.inf, 'infinite pixel') + ' (cyan)');
      if (parts.length) say('\'' + im.label + '\' has ' + parts.join(' and ') + '.');
    });
    if (D.missing && D.missing.length)
      say('Charts not found in the bench folder (--no-charts, or the chart script failed): ' +
        D.missing.join(', ') + '.');
  }

  /* ---- tables ---- */
  function table(head, rows) {
    return el('table', {}, el('thead', {}, el('tr', {}, ...head.map((h) => el('th', { text: h })))),
      el('tbody', {}, ...rows.map((r) => el('tr', {}, ...r.map((c) => el('td', { text: c }))))));
  }
  function parseCSV(t) {
    const rows = [];
    let row = [], f = '', q = false;
    for (let i = 0; i < t.length; i++) {
      const c = t[i];
      if (q) {
        if (c !== '"') f += c;
        else if (t[i + 1] === '"') { f += '"'; i++; } else q = false;
      } else if (c === '"') q = true;
      else if (c === ',') { row.push(f); f = ''; }
      else if (c === '\n') { row.push(f); rows.push(row); row = []; f = ''; }
      else if (c !== '\r') f += c;
    }
    if (f !== '' || row.length) { row.push(f); rows.push(row); }
    const head = rows.shift() || [];
    return rows.map((r) => Object.fromEntries(head.map((h, i) => [h, h === 'label' ? r[i] : parseFloat(r[i])])));
  }
  function meanSe(xs) {
    const n = xs.length, m = xs.reduce((a, b) => a + b, 0) / n;
    if (n < 2) return [m, NaN];
    const v = xs.reduce((a, b) => a + (b - m) * (b - m), 0) / (n - 1);
    return [m, Math.sqrt(v / n)];
  }
  function efficiency(s, c) { /* 1/(relMSE x cost) and its standard error (tools/bench_report.py) */
    const [e, se] = s.relmse, [k, sk] = s[c];
    if (!(e > 0 && k > 0)) return [NaN, NaN];
    const f = 1 / (e * k);
    return [f, f * Math.sqrt((se / e) ** 2 + ((sk === sk ? sk : 0) / k) ** 2)];
  }
  function ratio([a, sa], [b, sb]) {
    if (!(a > 0 && b > 0)) return [NaN, NaN];
    const r = a / b;
    return [r, r * Math.sqrt((sa / a) ** 2 + (sb / b) ** 2)];
  }
  function benchTables(sec) {
    const rows = parseCSV(D.text.csv), meta = D.text.bench ? JSON.parse(D.text.bench) : null;
    const labels = meta ? meta.variants : [...new Set(rows.map((r) => r.label))];
    const budgets = [...new Set(rows.map((r) => r.budget))].sort((a, b) => a - b);
    const unit = meta && meta.budget === 'seconds' ? 's' : 'spp';
    const cols = ['relmse', 'seconds', 'lookups', 'rays', 'nonfinite', 'max_sample'];
    const agg = labels.map((_, v) => Object.fromEntries(budgets.map((b) => {
      const sel = rows.filter((r) => r.variant === v && r.budget === b);
      if (!sel.length) return [b, null];
      return [b, Object.fromEntries(cols.map((c) => [c, meanSe(sel.map((r) => r[c]))]).concat([['n', sel.length]]))];
    })));
    const big = budgets[budgets.length - 1];
    const eff = (v, b, c) => (v ? pm(...ratio(efficiency(agg[v][b], c), efficiency(agg[0][b], c))) : '1');
    const summary = D.text.report && /## Summary\n\n([\s\S]*?)\n\n/.exec(D.text.report);
    sec.append(el('h2', { text: 'Summary' }));
    if (summary) sec.append(el('p', { text: summary[1] }));
    sec.append(el('h2', { text: 'At ' + big + ' ' + unit + ' (the images above)' }));
    sec.append(table(['variant', 'relMSE', 'seconds', 'density lookups', 'rays', 'efficiency vs first, equal time',
      'equal lookups', 'NaN/Inf', 'max sample'], labels.map((l, v) => {
      const s = agg[v][big];
      if (!s) return [l, 'no renders', '', '', '', '', '', '', ''];
      return [l, pm(...s.relmse), pm(...s.seconds), g3(s.lookups[0]), g3(s.rays[0]), eff(v, big, 'seconds'),
        eff(v, big, 'lookups'), String(Math.round(s.nonfinite[0] * s.n)), g3(s.max_sample[0])];
    })));
    const all = [];
    budgets.forEach((b) => labels.forEach((l, v) => {
      const s = agg[v][b];
      if (s) all.push([l, String(b), pm(...s.relmse), pm(...s.seconds), g3(s.lookups[0]), eff(v, b, 'seconds'),
        eff(v, b, 'lookups')]);
    }));
    const every = 'Every budget (' + budgets.join(', ') + ' ' + unit + '; mean \u00b1 standard error over the seeds)';
    sec.append(el('details', {}, el('summary', { text: every }), table(['variant', 'budget', 'relMSE', 'seconds',
      'density lookups', 'efficiency vs first, equal time', 'equal lookups'], all)));
    sec.append(el('p', { text: 'relMSE = mean over pixels and channels of ((a \u2212 r)\u00b2 \u2212 v) / ' +
      '(r\u00b2 + 0.01), the reference\u2019s own noise v subtracted; efficiency = 1 / (relMSE \u00d7 cost). ' +
      'Each image above is the first seed\u2019s render at ' + big + ' ' + unit + '; its error map (efficiency ' +
      'views) is the mean over all ' + (meta ? meta.repeat + ' ' : '') + 'seeds.' }));
  }
  function compareTable(sec) {
    const f = JSON.parse(D.text.figures), rows = [['MSE', g3(f.mse)], ['relMSE', pm(f.relmse, f.relmse_se)],
      ['mean absolute relative error', g3(f.mare)],
      ['mean difference a \u2212 r', pm(f.diff[3], f.diff_se[3]) + '  (z = ' + f.z.toFixed(2) + (Math.abs(f.z) < 3 ?
        ': no sign of a different expected image)' : ': the expected images differ)')],
      ['pixel-channels compared', String(f.n)], ['NaN/Inf pixel-channels skipped', String(f.nonfinite)]];
    if (f.efficiency_time)
      rows.push(['efficiency 1/(relMSE \u00d7 seconds)', g3(f.efficiency_time) + '  (' + g3(f.seconds) + ' s)']);
    if (f.efficiency_lookups) rows.push(['efficiency 1/(relMSE \u00d7 lookups)', g3(f.efficiency_lookups)]);
    sec.append(el('h2', { text: 'Figures (murk compare)' }), table(['', f.test + ' against ' + f.reference], rows));
  }
  function sections() {
    const sec = $('tables');
    try {
      if (D.text.csv) benchTables(sec);
      else if (D.text.figures) compareTable(sec);
    } catch (err) {
      sec.append(el('p', { class: 'notice', text: 'The tables could not be made: ' + err }));
    }
    if (D.charts.length) {
      $('charts').append(el('h2', { text: 'Charts' }));
      D.charts.forEach((c) => $('charts').append(el('figure', {}, el('img', { src: c.uri, alt: c.title }),
        el('figcaption', { text: c.title }))));
    }
    if (D.text.report)
      $('report').append(el('details', {}, el('summary', { text: 'report.md' }), el('pre', { text: D.text.report })));
    if (D.text.bench)
      $('report').append(el('details', {}, el('summary', { text: 'bench.json' }), el('pre', { text: D.text.bench })));
  }

  document.title = D.title;
  $('title').textContent = D.title;
  const meta = D.text.bench ? JSON.parse(D.text.bench) : null;
  $('subtitle').textContent = meta ? meta.command : D.text.command || '';
  $('footer').textContent = 'murk comparison page: ' + IM.length + ' images of ' + W + '\u00d7' + H + ' as half ' +
    'floats; image data ' + mib(D.bytes) + ' of its ' + mib(D.limit) + ' limit (MURK_MAX_PAGE_BYTES). Nothing is ' +
    'loaded from outside this file.';
  buildControls();
  notices();
  sections();
  bindView();
  resize();
  update();
  window.murkPage = {
    ready: true, state: S, width: W, height: H, labels: IM.map((im) => im.label),
    imageToCanvas: (x, y) => [S.ox + (x + 0.5) * S.zoom, S.oy + (y + 0.5) * S.zoom],
    canvasToClient: (cx, cy) => {
      const r = canvas.getBoundingClientRect();
      return [r.left + cx / dpr(), r.top + cy / dpr()];
    },
  };
})();
