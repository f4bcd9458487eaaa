// btfsm view: applies the per-step status changes of the JSON data block to
// the diagrams (fill of each node's shapes), moves the timeline cursors and
// the robots on the map, and
// drives the slider, buttons and keys. Hand-written, no library; inlined by
// src/view/html.rs. A jump restores the nearest checkpoint (one every
// D.checkpoint steps, made once at load) and applies at most that many steps.
(function () {
  'use strict';
  var D = JSON.parse(document.getElementById('btfsm-data').textContent);
  var N = D.checkpoint;
  var slider = document.getElementById('slider');
  var pos = document.getElementById('pos');
  var total = 0;

  function apply(s, d) {
    for (var j = 0; j < d.length; j += 2) s[d[j]] = d[j + 1];
  }

  var panels = D.panels.map(function (p, i) {
    var n = p.ids.length, s = new Uint8Array(n), cps = [];
    for (var k = 0; k < p.times.length; k++) {
      apply(s, p.deltas[k]);
      if (k % N === 0) cps.push(s.slice());
    }
    total = Math.max(total, p.times.length);
    return {
      p: p, pre: 'p' + i + '-', cur: new Uint8Array(n), shown: new Uint8Array(n),
      step: -1, cps: cps, shapes: new Array(n),
      cursor: document.getElementById('p' + i + '-cursor'),
      now: document.getElementById('p' + i + '-now')
    };
  });

  // The shapes to fill for node n: its node's outline shapes, and the
  // background of its cluster when it is an HFSM container.
  function shapesOf(P, n) {
    if (P.shapes[n]) return P.shapes[n];
    var out = [], id = P.p.ids[n];
    var node = document.getElementById(P.pre + id);
    if (node) {
      var list = node.querySelectorAll('ellipse, polygon, path');
      for (var j = 0; j < list.length; j++) out.push(list[j]);
    }
    var cl = document.getElementById(P.pre + 'c_' + id.slice(2));
    if (cl) {
      var c = cl.querySelector('polygon, path');
      if (c) out.push(c);
    }
    P.shapes[n] = out;
    return out;
  }

  function paint(P) {
    for (var n = 0; n < P.cur.length; n++) {
      if (P.cur[n] === P.shown[n]) continue;
      var fill = D.fill[P.cur[n]] || '';
      var sh = shapesOf(P, n);
      for (var j = 0; j < sh.length; j++) sh[j].style.fill = fill;
      P.shown[n] = P.cur[n];
    }
  }

  function goPanel(P, k) {
    var len = P.p.times.length;
    if (len === 0) return;
    k = Math.min(k, len - 1);
    if (k !== P.step) {
      var from;
      if (P.step >= 0 && k > P.step && k - P.step <= N) {
        from = P.step + 1;
      } else {
        var c = Math.floor(k / N);
        P.cur.set(P.cps[c]);
        from = c * N + 1;
      }
      for (var j = from; j <= k; j++) apply(P.cur, P.p.deltas[j]);
      P.step = k;
      paint(P);
    }
    var t = P.p.times[k];
    if (P.cursor) {
      var x = P.p.axis.x0 + t * P.p.axis.scale;
      P.cursor.setAttribute('x1', x);
      P.cursor.setAttribute('x2', x);
    }
    if (P.now) {
      var running = [];
      for (var n = 0; n < P.cur.length && running.length < 8; n++) {
        if (P.cur[n] === 1) running.push(P.p.keys[n]);
      }
      P.now.textContent = 't = ' + t.toFixed(P.p.digits) + ' s' + (k < current ? ' (ended at step ' + k + ')' : '') +
        (running.length ? ' · RUNNING: ' + running.join(', ') : '');
    }
  }

  // The map: each panel's robot at the last position recorded at or
  // before step k (tracks are [step, x, y, ...], steps ascending).
  var robots = D.map ? D.map.map(function (tr, i) {
    return { tr: tr, el: document.getElementById('map-robot-' + i) };
  }) : [];
  function moveRobots(k) {
    for (var i = 0; i < robots.length; i++) {
      var R = robots[i], tr = R.tr, lo = 0, hi = tr.length / 3 - 1;
      if (!R.el || hi < 0) continue;
      if (tr[0] > k) { R.el.setAttribute('visibility', 'hidden'); continue; }
      while (lo < hi) {
        var mid = (lo + hi + 1) >> 1;
        if (tr[3 * mid] <= k) lo = mid; else hi = mid - 1;
      }
      R.el.setAttribute('cx', tr[3 * lo + 1]);
      R.el.setAttribute('cy', tr[3 * lo + 2]);
      R.el.setAttribute('visibility', 'visible');
    }
  }

  var current = 0;
  function go(k) {
    k = Math.max(0, Math.min(total - 1, k | 0));
    current = k;
    slider.value = k;
    for (var i = 0; i < panels.length; i++) goPanel(panels[i], k);
    moveRobots(k);
    var t = panels.length && panels[0].p.times.length ? panels[0].p.times[Math.min(k, panels[0].p.times.length - 1)] : 0;
    pos.textContent = 'step ' + k + ' / ' + (total - 1) + ' · t = ' + t.toFixed(panels.length ? panels[0].p.digits : 2) + ' s';
    document.body.setAttribute('data-step', k);
    if (history.replaceState) history.replaceState(null, '', '#step=' + k);
  }

  var timer = null;
  function play() {
    if (timer) { clearInterval(timer); timer = null; return; }
    var stride = Math.max(1, Math.round(total / 400));
    timer = setInterval(function () {
      if (current >= total - 1) { clearInterval(timer); timer = null; return; }
      go(current + stride);
    }, 40);
  }

  slider.addEventListener('input', function () { go(+slider.value); });
  document.getElementById('first').onclick = function () { go(0); };
  document.getElementById('prev').onclick = function () { go(current - 1); };
  document.getElementById('next').onclick = function () { go(current + 1); };
  document.getElementById('last').onclick = function () { go(total - 1); };
  document.getElementById('play').onclick = play;
  var gos = document.querySelectorAll('button.go');
  for (var g = 0; g < gos.length; g++) {
    gos[g].onclick = function () { go(D.divergences[+this.getAttribute('data-div')].step); };
  }
  document.addEventListener('keydown', function (e) {
    if (e.target === slider && e.key.indexOf('Arrow') === 0) return;
    var k = { ArrowRight: 1, ArrowLeft: -1, PageDown: 10, PageUp: -10 }[e.key];
    if (k) { go(current + k); e.preventDefault(); }
    else if (e.key === 'Home') { go(0); e.preventDefault(); }
    else if (e.key === 'End') { go(total - 1); e.preventDefault(); }
    else if (e.key === ' ') { play(); e.preventDefault(); }
  });
  var m = /step=(\d+)/.exec(location.hash);
  window.btfsmView = { go: go, step: function () { return current; }, total: total };
  go(m ? +m[1] : 0);
})();
