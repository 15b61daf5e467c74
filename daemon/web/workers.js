// workers.js — the worker slots (/workers): what runs where, the backend and
// the machine's load, from /api/v1/workers every two seconds.
'use strict';
(async () => {
  await mc.start();
  mc.every(2000, async () => {
    const w = await mc.api('/workers');
    const busy = w.slots.filter((s) => s.state !== 'idle').length;
    const load = w.load.map((x) => (x === null ? '?' : x.toFixed(2))).join(' ');
    document.getElementById('summary').textContent =
      'Backend ' + w.backend + ': ' + busy + ' of ' + w.slots.length + ' slot(s) busy; load average ' + load;
    const rows = w.slots.map((s) => {
      const tr = document.createElement('tr');
      tr.appendChild(mc.el('td', s.slot));
      tr.appendChild(mc.el('td', s.state));
      const job = document.createElement('td');
      if (s.job !== null) {
        const a = mc.el('a', s.job);
        a.href = '/jobs/' + s.job;
        job.appendChild(a);
      } else if (s.state !== 'idle') {
        job.textContent = 'another user\u2019s';
      }
      tr.appendChild(job);
      tr.appendChild(mc.el('td', s.user || ''));
      tr.appendChild(mc.el('td', s.label || '', 'label'));
      tr.appendChild(mc.el('td', s.stage));
      const pr = document.createElement('td');
      if (s.state !== 'idle') pr.appendChild(mc.progress(s.progress));
      tr.appendChild(pr);
      tr.appendChild(mc.el('td', s.state === 'idle' ? '' : mc.duration(s.elapsed_s)));
      tr.appendChild(mc.el('td', s.state === 'idle' ? '' : mc.duration(s.eta_s)));
      return tr;
    });
    document.querySelector('#slots tbody').replaceChildren(...rows);
  });
})();
