// list.js — the job list (/): /api/v1/jobs every two seconds, filtered by
// state and (for admins) user; each row links to its job's page.
'use strict';
(async () => {
  await mc.start();
  const state = document.getElementById('state'), user = document.getElementById('user');
  if (mc.session.admin) document.getElementById('userfilter').hidden = false;
  const q = new URLSearchParams(location.search);
  state.value = q.get('state') || '';
  user.value = q.get('user') || '';
  let refresh = async () => {};
  const changed = () => {
    const p = new URLSearchParams();
    if (state.value) p.set('state', state.value);
    if (user.value) p.set('user', user.value);
    history.replaceState(null, '', p.toString() ? '/?' + p : '/');
    refresh();
  };
  state.addEventListener('change', changed);
  user.addEventListener('change', changed);
  document.getElementById('filters').addEventListener('submit', (e) => { e.preventDefault(); changed(); });
  refresh = async () => {
    const p = new URLSearchParams();
    if (state.value) p.set('state', state.value);
    if (user.value && mc.session.admin) p.set('user', user.value);
    const data = await mc.api('/jobs' + (p.toString() ? '?' + p : ''));
    const body = document.querySelector('#jobs tbody');
    const rows = [];
    for (const j of data.jobs) {
      const tr = document.createElement('tr');
      tr.id = 'job-' + j.id;
      const a = mc.el('a', j.id);
      a.href = '/jobs/' + j.id;
      const id = document.createElement('td');
      id.appendChild(a);
      tr.appendChild(id);
      tr.appendChild(mc.el('td', j.label, 'label'));
      tr.appendChild(mc.el('td', j.user));
      tr.appendChild(mc.el('td', j.state, 'state-' + j.state));
      tr.appendChild(mc.el('td', j.stage));
      const pr = document.createElement('td');
      pr.appendChild(mc.progress(j.progress));
      pr.appendChild(mc.el('span', ' ' + mc.percent(j.progress)));
      tr.appendChild(pr);
      tr.appendChild(mc.el('td', j.state === 'RUNNING' ? mc.duration(j.eta_s) : ''));
      tr.appendChild(mc.el('td', j.queue_position === null ? '' : j.queue_position + ' ahead'));
      tr.appendChild(mc.el('td', mc.duration(j.elapsed_s)));
      const qc = document.createElement('td');
      qc.appendChild(mc.verdict(j.quality));
      tr.appendChild(qc);
      rows.push(tr);
    }
    body.replaceChildren(...rows);
    document.getElementById('status').textContent =
      data.jobs.length + ' job(s), updated ' + new Date().toLocaleTimeString();
  };
  mc.every(2000, refresh);
})();
