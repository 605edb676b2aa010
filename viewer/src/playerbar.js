// Play / pause / scrub bar for the selected plan's trajectory.
import { el } from './dom.js';

export function createPlayerBar(container, requestRender) {
  let player = null;
  const button = el('button', { id: 'play', title: 'play / pause (space)', onclick: () => bar.toggle() }, '▶');
  const slider = el('input', { type: 'range', id: 'scrub', min: 0, max: 1000, value: 0,
    oninput: (e) => { if (player) { player.playing = false; player.set((e.target.value / 1000) * player.duration); } } });
  const label = el('span', {});
  const phase = el('span', { class: 'phase' });
  const time = el('span', { class: 'time' });
  const box = el('div', { id: 'player', class: 'overlay', style: 'display:none' }, button, label, slider, phase, time);
  container.append(box);
  const bar = {
    setPlayer(p, text = '') {
      player = p;
      box.style.display = p ? 'flex' : 'none';
      label.textContent = text;
      bar.update();
    },
    update() {
      if (!player) return;
      slider.value = String(Math.round((1000 * player.t) / (player.duration || 1)));
      time.textContent = `${player.t.toFixed(2)} / ${player.duration.toFixed(2)} s`;
      phase.textContent = phaseName(player);
      button.textContent = player.playing ? '❚❚' : '▶';
    },
    play() {
      if (!player) return;
      if (player.t >= player.duration) player.set(0);
      player.playing = true;
      bar.update();
      requestRender();
    },
    toggle() { if (player?.playing) { player.playing = false; bar.update(); } else bar.play(); },
    tick: (t) => (player ? player.tick(t) : false),
  };
  return bar;
}

const PHASES = { waypoint: 'extract', lift: 'lift', travel: 'travel', place: 'descend' };

function phaseName(player) {
  if (player.t <= 0) return 'grasp';
  if (player.t >= player.duration) return 'placed';
  const next = player.keys.find((k) => k.t >= player.t);
  return PHASES[next?.tag] || '';
}
