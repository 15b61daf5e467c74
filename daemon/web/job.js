// job.js — one job's page (/jobs/ID): its facts and progress from
// /api/v1/jobs/ID, its quality, and a plot of every energy term and beta
// against the iteration over all stages (log scale: the terms span
// decades), drawn as SVG from the job's event stream
// (/api/v1/jobs/ID/events); once it completed, the picture of its
// map. Cancel for the owner and admins.
'use strict';
(async () => {
  await mc.start();
  const id = location.pathname.split('/')[2];
  const SVG = 'http://www.w3.org/2000/svg';
  const series = ['membrane', 'bending', 'mismatch', 'reverse', 'energy', 'beta'];
  const points = [];
  let after = 0, ended = false;

  const legend = document.getElementById('legend');
  series.forEach((name, i) => {
    const s = mc.el('span');
    s.appendChild(mc.el('span', null, 'swatch s' + i));
    s.appendChild(document.createTextNode(name === 'beta' ? '\u03b2' : name));
    legend.appendChild(s);
  });

  function svg(tag, attrs, text) {
    const e = document.createElementNS(SVG, tag);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function draw() {
    const plot = document.getElementById('plot');
    const W = 900, H = 360, L = 60, R = 20, T = 14, B = 34;
    let lo = Infinity, hi = -Infinity;
    for (const p of points)
      for (const k of series)
        if (p[k] > 0) { lo = Math.min(lo, p[k]); hi = Math.max(hi, p[k]); }
    const kids = [];
    plot.dataset.points = String(points.length);
    if (!points.length || !(hi > 0)) {
      kids.push(svg('text', { x: L, y: H / 2 }, 'no progress yet'));
      plot.replaceChildren(...kids);
      return;
    }
    const d0 = Math.floor(Math.log10(lo)), d1 = Math.max(Math.ceil(Math.log10(hi)), d0 + 1);
    const n = points.length;
    const x = (i) => L + (n > 1 ? (i / (n - 1)) * (W - L - R) : 0);
    const y = (v) => T + (1 - (Math.log10(v) - d0) / (d1 - d0)) * (H - T - B);
    for (let d = d0; d <= d1; d++) {
      kids.push(svg('line', { x1: L, x2: W - R, y1: y(10 ** d), y2: y(10 ** d), class: 'grid' }));
      kids.push(svg('text', { x: 4, y: y(10 ** d) + 4 }, '1e' + d));
    }
    // a dashed line where each stage starts; its name when there is room
    let stage = null, lastLabel = -Infinity;
    points.forEach((p, i) => {
      if (p.stage !== stage) {
        stage = p.stage;
        kids.push(svg('line', { x1: x(i), x2: x(i), y1: T, y2: H - B, class: 'stage' }));
        if (x(i) - lastLabel >= 48) {
          kids.push(svg('text', { x: x(i) + 3, y: H - B + 14 }, stage));
          lastLabel = x(i);
        }
      }
    });
    kids.push(svg('text', { x: W - R - 150, y: H - 6 }, 'iteration (all stages): ' + n));
    series.forEach((k, s) => {
      const xy = [];
      points.forEach((p, i) => { if (p[k] > 0) xy.push(x(i).toFixed(1) + ',' + y(p[k]).toFixed(1)); });
      if (xy.length) kids.push(svg('polyline', { points: xy.join(' '), class: 's' + s, 'data-series': k }));
    });
    plot.replaceChildren(...kids);
  }

  function fact(dl, name, value) {
    dl.appendChild(mc.el('dt', name));
    const dd = mc.el('dd');
    if (value instanceof Node) dd.appendChild(value); else dd.textContent = value;
    dl.appendChild(dd);
  }

  async function refreshJob() {
    const j = await mc.api('/jobs/' + id);
    document.title = 'meshcorr — job ' + j.id;
    document.getElementById('title').textContent = 'Job ' + j.id + (j.label ? ': ' + j.label : '');
    const facts = mc.el('dl');
    facts.id = 'facts';
    fact(facts, 'User', j.user);
    fact(facts, 'State', mc.el('span', j.state, 'state-' + j.state));
    fact(facts, 'Stage', j.stage || '—');
    if (j.queue_position !== null) fact(facts, 'Queue', j.queue_position + ' job(s) ahead');
    fact(facts, 'Elapsed', mc.duration(j.elapsed_s));
    if (j.state === 'RUNNING') fact(facts, 'Time left', mc.duration(j.eta_s));
    fact(facts, 'Priority', j.priority);
    if (j.reason) fact(facts, 'Reason', j.reason);
    document.getElementById('facts').replaceWith(facts);
    const bar = document.getElementById('progress');
    if (j.progress !== null) bar.value = j.progress; else bar.removeAttribute('value');
    document.getElementById('percent').textContent = mc.percent(j.progress);
    document.getElementById('params').textContent = j.params.split(' ').join('\n');
    const cancel = document.getElementById('cancel');
    ended = !['PENDING', 'RUNNING'].includes(j.state);
    cancel.hidden = ended;
    if (j.state === 'COMPLETED') {
      if (document.getElementById('result').hidden) showPicture();
      document.getElementById('result').hidden = false;
      document.getElementById('map-p').href = '/api/v1/jobs/' + id + '/maps/p';
      document.getElementById('map-q').href = '/api/v1/jobs/' + id + '/maps/q';
    }
    const q = await mc.api('/jobs/' + id + '/quality');
    const ql = mc.el('dl');
    ql.id = 'quality';
    fact(ql, 'Verdict', mc.verdict(j.quality));
    if (j.quality.flipped !== null) fact(ql, 'Flipped faces', mc.percent(j.quality.flipped));
    if (j.quality.collapsed !== null) fact(ql, 'Collapsed faces', mc.percent(j.quality.collapsed));
    for (const k in q.metrics) fact(ql, k, q.metrics[k] === null ? '—' : Number(q.metrics[k]).toPrecision(4));
    document.getElementById('quality').replaceWith(ql);
  }

  // The map's picture is drawn by the server on the first request (503
  // until it is there): asked again every second, then shown.
  async function showPicture() {
    const url = '/api/v1/jobs/' + id + '/picture';
    const msg = document.getElementById('picture-msg');
    for (let i = 0; i < 300; i++) {
      const r = await fetch(url, { credentials: 'same-origin' });
      if (r.ok) {
        const img = document.getElementById('picture');
        img.src = url;
        img.hidden = false;
        msg.hidden = true;
        return;
      }
      if (r.status !== 503) {
        msg.textContent = 'No picture: ' + ((await r.json()).error || r.statusText);
        return;
      }
      await new Promise((res) => setTimeout(res, 1000));
    }
    msg.textContent = 'No picture yet: reload the page to try again.';
  }

  // The plot follows the job's event stream (the browser reconnects with
  // the last record's id); a stream the server refuses (all taken) falls
  // back to reading the history every two seconds.
  let drawing = null;
  function drawSoon() {
    if (!drawing) drawing = setTimeout(() => { drawing = null; draw(); }, 200);
  }

  async function poll() {
    for (;;) {
      const h = await mc.api('/jobs/' + id + '/history?after=' + after);
      points.push(...h.points);
      after = h.next;
      if (!h.points.length) break;
    }
    drawSoon();
  }

  function follow() {
    const es = new EventSource('/api/v1/jobs/' + id + '/events');
    document.getElementById('plot').dataset.live = 'events';
    es.addEventListener('progress', (e) => {
      points.push(JSON.parse(e.data));
      after = Number(e.lastEventId);
      drawSoon();
    });
    es.addEventListener('end', () => { es.close(); drawSoon(); });
    es.addEventListener('error', () => {
      if (es.readyState === EventSource.CLOSED) {
        document.getElementById('plot').dataset.live = 'polling';
        mc.every(2000, poll);
      }
    });
  }

  document.getElementById('cancel').addEventListener('click', async () => {
    const msg = document.getElementById('cancelmsg');
    try {
      await mc.post('/jobs/' + id + '/cancel');
      msg.textContent = 'cancel requested';
    } catch (e) {
      msg.textContent = e.message;
    }
  });

  draw();
  follow();
  mc.every(1000, refreshJob);
})();
