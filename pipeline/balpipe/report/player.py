"""A small self-contained canvas player: the mechanism moving on its free-floating frame.

The page embeds, per stage, the outline of every body (local points) and its pose at about 60
frames, plus the frame's pose; a few lines of JavaScript draw them side by side. Controls:
play/pause, a time slider, the speed (real time by default, the time scale shown); keyboard:
Tab to the canvas, space to pause, arrows to step. No library, no external file.
"""

from __future__ import annotations

import json

import numpy as np

from ..model import Model

FRAMES = 60


def _outline(model: Model) -> list[dict]:
    shapes = []
    for b in model.bodies:
        pts = [b.points[p] for p in b.outline] if len(b.outline) >= 2 else []
        cws = [[round(a.position[0], 5), round(a.position[1], 5), round(a.mass, 4)]
               for a in b.attachments if a.kind == "counterweight"]
        gears = [[round(a.position[0], 5), round(a.position[1], 5), round(a.radius, 5)]
                 for a in b.attachments if a.radius and a.kind != "counterweight"]
        shapes.append({
            "line": [[round(p[0], 5), round(p[1], 5)] for p in pts],
            "radius": round(b.radius, 5) if b.radius else 0,
            "slider": b.kind == "slider",
            "cw": cws,
            "gears": gears,
        })
    return shapes


def _extent_points(model: Model, poses: np.ndarray) -> np.ndarray:
    """Global positions of every named point, attachment and disc rim over the frames."""
    out = [poses[:, :, :2].reshape(-1, 2)]
    for i, b in enumerate(model.bodies):
        local = list(b.points.values()) + [a.position for a in b.attachments]
        r = max([b.radius or 0.0] + [(a.radius or 0.0) for a in b.attachments])
        if r:
            local += [(r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)]
        x, y, th = poses[:, i, 0], poses[:, i, 1], poses[:, i, 2]
        for px, py in local:
            out.append(np.stack([x + np.cos(th) * px - np.sin(th) * py, y + np.sin(th) * px + np.cos(th) * py], axis=1))
    pts = np.vstack(out)
    fp = np.array(list(model.frame_points.values()) or [[0.0, 0.0]])
    return np.vstack([pts, fp])


def player_html(stages: list[dict], element_id: str = "player") -> str:
    """``stages``: dicts with label, model, t (n,), base (n, 3) frame-origin poses and poses
    (n, nb, 3) body-frame poses, all in the global frame of the start."""
    data = []
    lo = np.array([np.inf, np.inf])
    hi = -lo
    for s in stages:
        n = len(s["t"])
        ks = np.unique(np.linspace(0, n - 1, min(n, FRAMES)).round().astype(int))
        poses = s["poses"][ks]
        base = s["base"][ks]
        xy = _extent_points(s["model"], poses)
        lo, hi = np.minimum(lo, xy.min(axis=0)), np.maximum(hi, xy.max(axis=0))
        fp = [[round(p[0], 5), round(p[1], 5)] for p in s["model"].frame_points.values()]
        data.append({
            "label": s["label"],
            "t": [round(float(v), 5) for v in s["t"][ks]],
            "base": [[round(float(v), 6) for v in row] for row in base],
            "poses": [[[round(float(v), 6) for v in body] for body in frame] for frame in poses],
            "shapes": _outline(s["model"]),
            "pivots": fp,
            "guides": [[[round(a[0], 5), round(a[1], 5)], [round(b[0], 5), round(b[1], 5)]] for a, b in s["model"].guides],
        })
    pad = 0.15 * float(max(hi - lo)) if np.all(np.isfinite(hi)) else 0.1
    box = [round(float(lo[0] - pad), 4), round(float(lo[1] - pad), 4), round(float(hi[0] + pad), 4), round(float(hi[1] + pad), 4)]
    payload = json.dumps({"stages": data, "box": box}, separators=(",", ":"), sort_keys=True)
    # names are data: no '</script>' or '<!--' can end the script early
    payload = payload.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    width = 300 * max(1, len(stages))
    eid = element_id
    return f"""<div class="player" id="{eid}-box">
<canvas id="{eid}" width="{width}" height="300" style="max-width:100%;border:1px solid #d9dee4" role="img" aria-label="Animation of the mechanism on its free-floating frame, one panel per stage"></canvas>
<div class="player-controls">
<button type="button" id="{eid}-play" aria-controls="{eid}" aria-label="Pause">Pause</button>
<label for="{eid}-time">time</label>
<input type="range" id="{eid}-time" min="0" max="1000" step="1" value="0" aria-label="Time along the motion">
<label for="{eid}-speed">speed</label>
<select id="{eid}-speed" aria-label="Playback speed"><option value="0.1">0.1×</option><option value="0.25">0.25×</option><option value="0.5">0.5×</option><option value="1" selected>1× (real time)</option><option value="2">2×</option><option value="4">4×</option></select>
<output id="{eid}-clock" for="{eid}-time" aria-live="off"></output>
</div>
</div>
<script>
(function() {{
const D = {payload};
const cv = document.getElementById("{eid}"), g = cv.getContext("2d");
const btn = document.getElementById("{eid}-play"), slider = document.getElementById("{eid}-time");
const speedSel = document.getElementById("{eid}-speed"), clock = document.getElementById("{eid}-clock");
const W = 300, H = 300, b = D.box;
const T0 = D.stages[0].t[0], T1 = D.stages[0].t[D.stages[0].t.length - 1], span = Math.max(T1 - T0, 1e-9);
const s = Math.min(W / (b[2] - b[0]), (H - 40) / (b[3] - b[1]));
function P(x, y, k) {{ return [k * W + (x - b[0]) * s, H - 30 - (y - b[1]) * s]; }}
function T(pose, p) {{ const c = Math.cos(pose[2]), si = Math.sin(pose[2]);
  return [pose[0] + c * p[0] - si * p[1], pose[1] + si * p[0] + c * p[1]]; }}
function frameAt(st, time) {{ let i = 0; while (i + 1 < st.t.length && st.t[i + 1] <= time + 1e-12) i++; return i; }}
let time = T0, playing = true, last = null;
function draw() {{
  g.clearRect(0, 0, cv.width, cv.height);
  D.stages.forEach((st, k) => {{
    const i = frameAt(st, time), base = st.base[i];
    g.fillStyle = "#e8edf3"; g.strokeStyle = "#8aa4c0";
    g.beginPath(); st.pivots.forEach((p, j) => {{ const q = P(...T(base, p), k); j ? g.lineTo(...q) : g.moveTo(...q); }});
    g.closePath(); g.stroke();
    st.guides.forEach(gd => {{ const a = P(...T(base, gd[0]), k), e = P(...T(base, gd[1]), k);
      g.strokeStyle = "#8aa4c0"; g.beginPath(); g.moveTo(...a); g.lineTo(...e); g.stroke(); }});
    st.pivots.forEach(p => {{ const q = P(...T(base, p), k); g.fillStyle = "#22303f"; g.fillRect(q[0] - 4, q[1] - 4, 8, 8); }});
    st.shapes.forEach((sh, j) => {{
      const pose = st.poses[i][j];
      if (sh.radius) {{ const c = P(...T(pose, [0, 0]), k); g.strokeStyle = "#2e8b57"; g.beginPath();
        g.arc(c[0], c[1], sh.radius * s, 0, 2 * Math.PI); g.stroke(); const e = P(...T(pose, [sh.radius, 0]), k);
        g.beginPath(); g.moveTo(...c); g.lineTo(...e); g.stroke(); }}
      if (sh.slider) {{ const c = P(...T(pose, [0, 0]), k); g.fillStyle = "#ccc"; g.fillRect(c[0] - 8, c[1] - 5, 16, 10); }}
      sh.gears.forEach(gr => {{ const c = P(...T(pose, gr), k); g.strokeStyle = "#2e8b57"; g.beginPath();
        g.arc(c[0], c[1], gr[2] * s, 0, 2 * Math.PI); g.stroke(); }});
      sh.cw.forEach(cw => {{ const c = P(...T(pose, cw), k), o = P(...T(pose, [0, 0]), k);
        g.strokeStyle = "rgba(214,39,40,0.8)"; g.beginPath(); g.moveTo(...o); g.lineTo(...c); g.stroke();
        g.fillStyle = "rgba(214,39,40,0.6)"; g.beginPath();
        g.arc(c[0], c[1], 3 + 2 * Math.sqrt(cw[2]), 0, 2 * Math.PI); g.fill(); }});
      if (sh.line.length > 1) {{ g.strokeStyle = "#111"; g.lineWidth = 3; g.beginPath();
        sh.line.forEach((p, m) => {{ const q = P(...T(pose, p), k); m ? g.lineTo(...q) : g.moveTo(...q); }}); g.stroke(); g.lineWidth = 1; }}
    }});
    g.fillStyle = "#1d232b"; g.font = "12px sans-serif";
    g.fillText(st.label, k * W + 8, 16);
    const dx = base[0] * 1000, dy = base[1] * 1000, rot = base[2] * 180 / Math.PI;
    g.fillText(`frame: (${{dx.toFixed(2)}}, ${{dy.toFixed(2)}}) mm, ${{rot.toFixed(3)}} deg`, k * W + 8, H - 8);
  }});
  slider.value = String(Math.round(1000 * (time - T0) / span));
  clock.textContent = `t = ${{time.toFixed(3)}} s of ${{T1.toFixed(3)}} s · ${{speedSel.value}}× real time`;
}}
function tick(now) {{
  if (!playing) {{ last = null; return; }}
  if (last !== null) {{ time += (now - last) / 1000 * parseFloat(speedSel.value);
    if (time > T1) time = T0 + (time - T1) % span; }}
  last = now; draw(); requestAnimationFrame(tick);
}}
function setPlaying(on) {{ playing = on; btn.textContent = on ? "Pause" : "Play"; btn.setAttribute("aria-label", btn.textContent);
  cv.dataset.playing = on ? "1" : "0"; if (on) {{ last = null; requestAnimationFrame(tick); }} }}
btn.addEventListener("click", () => setPlaying(!playing));
slider.addEventListener("input", () => {{ setPlaying(false); time = T0 + span * parseInt(slider.value, 10) / 1000; draw(); }});
speedSel.addEventListener("change", draw);
cv.tabIndex = 0;
cv.addEventListener("keydown", ev => {{
  if (ev.key === " " || ev.key === "k") {{ ev.preventDefault(); setPlaying(!playing); }}
  else if (ev.key === "ArrowRight" || ev.key === "ArrowLeft") {{ ev.preventDefault(); setPlaying(false);
    time = Math.min(T1, Math.max(T0, time + (ev.key === "ArrowRight" ? 1 : -1) * span / 100)); draw(); }}
}});
draw(); setPlaying(!matchMedia("(prefers-reduced-motion: reduce)").matches);
}})();
</script>"""
