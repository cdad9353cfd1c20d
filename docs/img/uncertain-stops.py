"""Draws docs/img/uncertain-stops.svg: the first impact speed against how far
the stop lies into the stroke, for the uncertain-stop valve's three designs
(deterministic, probability-based `contact_uncertainty`, `standoff`), closing
and opening, sensors at 10 µs (docs/validation/uncertain-stops.md).

    python3 docs/img/uncertain-stops.py target/release/reldesign

Runs `reldesign sweep` on displaced plants (about 3 minutes: the
probability-based design takes 12 s to build) and writes the SVG; no
plotting library needed.
"""

import json
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "uncertain-stop-valve.toml"
SHIFTS_UM = [0, 5, 10, 15, 20]
DESIGNS = ["deterministic", "probability-based", "standoff"]
COLOURS = {"deterministic": "#d62728", "probability-based": "#1f77b4", "standoff": "#2ca02c"}


def variants(text):
    det = re.sub(r"(?m)^contact_uncertainty = .*$", "contact_uncertainty = 0.0", text)
    standoff = re.sub(
        r"(?m)^contact_uncertainty = .*$", "standoff = 25e-6\napproach_speed = 10e-3", text
    ).replace("landing = 6e-3", "landing = 9.125e-3", 1)
    return {"deterministic": det, "probability-based": text, "standoff": standoff}


def displaced(text, op, shift_um):
    d = shift_um * 1e-6
    if op == "closing":
        return re.sub(r"(?m)^z_min = 0\.0 ", f"z_min = {d:e} ", text)
    return re.sub(r"(?m)^z_max = 1e-3", f"z_max = {1e-3 - d:e}", text)


def impacts(binary, work):
    text = EXAMPLE.read_text()
    files = {}
    for name, body in variants(text).items():
        files[name] = work / f"{name}.toml"
        files[name].write_text(body)
    out = {}
    for op in ["closing", "opening"]:
        for shift in SHIFTS_UM:
            plant = work / f"plant-{op}-{shift}.toml"
            plant.write_text(displaced(text, op, shift))
            for name in ["probability-based", "standoff"]:
                run = subprocess.run(
                    [binary, "sweep", str(files["deterministic"]), "--plant", str(plant),
                     "--sample-periods", "1e-5", "--compare", str(files[name]), "--json"],
                    check=True, capture_output=True, text=True, stdin=subprocess.DEVNULL)
                for row in json.loads(run.stdout)["rows"]:
                    if row["operation"] != op:
                        continue
                    design = "deterministic" if row["design"] == str(files["deterministic"]) else name
                    v = row["impact_velocity"]
                    out[(op, design, shift)] = abs(v) * 1e3 if v is not None else float("nan")
    return out


def svg(data):
    w, h, left, top, pw, ph, gap = 760, 320, 60, 30, 300, 220, 80
    top_v = 110.0
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
             f'font-family="sans-serif" font-size="12">',
             f'<rect width="{w}" height="{h}" fill="white"/>']
    for k, op in enumerate(["closing", "opening"]):
        x0 = left + k * (pw + gap)
        x = lambda s: x0 + pw * s / SHIFTS_UM[-1]
        y = lambda v: top + ph * (1 - min(v, top_v) / top_v)
        parts.append(f'<rect x="{x0}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>')
        parts.append(f'<text x="{x0 + pw / 2}" y="{top - 10}" text-anchor="middle">{op}</text>')
        for s in SHIFTS_UM:
            parts.append(f'<text x="{x(s)}" y="{top + ph + 16}" text-anchor="middle">{s}</text>')
        for v in range(0, int(top_v) + 1, 20):
            parts.append(f'<text x="{x0 - 6}" y="{y(v) + 4}" text-anchor="end">{v}</text>')
            parts.append(f'<line x1="{x0}" x2="{x0 + pw}" y1="{y(v)}" y2="{y(v)}" stroke="#eee"/>')
        parts.append(f'<text x="{x0 + pw / 2}" y="{top + ph + 34}" text-anchor="middle">'
                     'stop displaced into the stroke [µm]</text>')
        for name in DESIGNS:
            pts = " ".join(f"{x(s):.1f},{y(data[(op, name, s)]):.1f}" for s in SHIFTS_UM)
            parts.append(f'<polyline points="{pts}" fill="none" stroke="{COLOURS[name]}" stroke-width="2"/>')
            for s in SHIFTS_UM:
                parts.append(f'<circle cx="{x(s):.1f}" cy="{y(data[(op, name, s)]):.1f}" r="3" '
                             f'fill="{COLOURS[name]}"/>')
    parts.append(f'<text x="14" y="{top + ph / 2}" transform="rotate(-90 14 {top + ph / 2})" '
                 'text-anchor="middle">first impact [mm/s]</text>')
    for i, name in enumerate(DESIGNS):
        lx = left + 20 + i * 220
        parts.append(f'<line x1="{lx}" x2="{lx + 24}" y1="{h - 12}" y2="{h - 12}" '
                     f'stroke="{COLOURS[name]}" stroke-width="2"/>')
        parts.append(f'<text x="{lx + 30}" y="{h - 8}">{name}</text>')
    parts.append("</svg>")
    return "\n".join(parts) + "\n"


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target" / "release" / "reldesign")
    with tempfile.TemporaryDirectory() as tmp:
        data = impacts(binary, pathlib.Path(tmp))
    (ROOT / "docs" / "img" / "uncertain-stops.svg").write_text(svg(data))
    for key in sorted(data):
        print(*key, f"{data[key]:.2f} mm/s")


if __name__ == "__main__":
    main()
