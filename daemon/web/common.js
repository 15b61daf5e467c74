// common.js — what every page shares: the session (user, admin flag, CSRF
// token), the JSON API, the header's logout, and formatting.
'use strict';
const mc = {
  session: null,

  async api(path, opts) {
    const r = await fetch('/api/v1' + path, Object.assign({ credentials: 'same-origin' }, opts || {}));
    if (r.status === 401) {
      location.href = '/login';
      throw new Error('logged out');
    }
    const body = await r.json();
    if (!r.ok) throw new Error(body.error || r.statusText);
    return body;
  },

  post(path) {
    return mc.api(path, { method: 'POST', headers: { 'X-CSRF-Token': mc.session.csrf || '' } });
  },

  async start() {
    mc.session = await mc.api('/session');
    document.getElementById('who').textContent = mc.session.user + (mc.session.admin ? ' (admin)' : '');
    document.getElementById('logout').addEventListener('click', async () => {
      await fetch('/logout', { method: 'POST', headers: { 'X-CSRF-Token': mc.session.csrf || '' } });
      location.href = '/login';
    });
  },

  // Repeats fn every ms milliseconds, each run after the previous ended.
  every(ms, fn) {
    const run = async () => {
      try { await fn(); } catch (e) { console.log(e); }
      setTimeout(run, ms);
    };
    run();
  },

  el(tag, text, cls) {
    const e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = String(text);
    if (cls) e.className = cls;
    return e;
  },

  duration(s) {
    if (s === null || s === undefined) return '—';
    s = Math.round(s);
    const h = Math.floor(s / 3600), m = Math.floor((s % 3600) / 60), x = s % 60;
    if (h) return h + 'h' + String(m).padStart(2, '0') + 'm';
    if (m) return m + 'm' + String(x).padStart(2, '0') + 's';
    return x + 's';
  },

  percent(f) {
    return f === null || f === undefined ? '' : (100 * f).toFixed(f < 1 ? 1 : 0) + ' %';
  },

  progress(f) {
    const p = document.createElement('progress');
    p.max = 1;
    if (f !== null && f !== undefined) p.value = f;
    return p;
  },

  verdict(q) {
    if (!q || q.verdict === null) return mc.el('span', '—', 'muted');
    return mc.el('span', q.verdict, q.verdict === 'ok' ? 'verdict-ok' : 'verdict-bad');
  },
};
