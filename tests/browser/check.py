#!/usr/bin/env python3
"""Opens the HTML view (`pfaff simulate MODEL --animate FILE.html`) in headless Chromium.

For each model that exists in the registry: writes its HTML, opens it at two times
(`#t=...` opens the viewer paused there), takes a screenshot at each, and checks that
the page reports itself ready without a script error and that the drawing (a digest of
the canvas pixels the page computes) differs between the two times. Then a run of 1e5
output steps: its file must be under 20 MB and open (navigation start to the first
drawing, measured by the page) in under 2 s. Standard library only.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

MODELS = ["slider_crank_bodies", "bicycle", "bouncing_ball"]
# The models whose first screenshot the README shows (--docs).
README_MODELS = ["slider_crank_bodies", "bicycle"]
EMBED = re.compile(r'<script type="application/json" id="pfaff-trajectory">(.*?)</script>', re.S)


def run(cmd, **kw):
    return subprocess.run(cmd, check=False, capture_output=True, text=True, **kw)


class Browser:
    def __init__(self, exe, profile):
        self.exe = exe
        self.profile = profile

    def _args(self, extra, url):
        return [self.exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                "--no-first-run", "--disable-extensions", "--disable-background-networking",
                f"--user-data-dir={self.profile}", "--window-size=1100,640",
                "--enable-logging=stderr", "--v=0", "--virtual-time-budget=3000", *extra, url]

    def dom(self, url):
        p = run(self._args(["--dump-dom"], url), timeout=120)
        return p.stdout, p.stderr

    def screenshot(self, url, png):
        p = run(self._args([f"--screenshot={png}"], url), timeout=120)
        return p.stderr


def attrs(dom):
    m = re.search(r"<body([^>]*)>", dom)
    return dict(re.findall(r'([\w-]+)="([^"]*)"', m.group(1))) if m else {}


def console_errors(stderr):
    return [l for l in stderr.splitlines() if "CONSOLE" in l and ("Uncaught" in l or "Error" in l)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pfaff", required=True)
    ap.add_argument("--chromium", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--docs", help="copy the README's screenshots here as screenshot-MODEL.png")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    out = os.path.abspath(a.out)
    profile = tempfile.mkdtemp(prefix="pfaff-chromium-")
    browser = Browser(a.chromium, profile)
    listed = run([a.pfaff, "list"]).stdout
    names = {l.split()[0] for l in listed.splitlines() if l.strip()}
    passed, failed = 0, 0

    def check(ok, what):
        nonlocal passed, failed
        print(("ok     " if ok else "FAILED ") + what, flush=True)
        if ok:
            passed += 1
        else:
            failed += 1
        return ok

    for model in MODELS:
        if model not in names:
            print(f"note   {model}: not in the registry (`pfaff list`); skipped")
            continue
        html = os.path.join(out, f"{model}.html")
        sim = run([a.pfaff, "simulate", model, "--animate", html])
        if not check(sim.returncode == 0 and os.path.exists(html),
                     f"{model}: pfaff simulate --animate ({sim.stderr.strip()[:200]})"):
            continue
        data = json.loads(EMBED.search(open(html, encoding="utf-8").read()).group(1))
        t = data["times"]
        span = t[-1] - t[0]
        digests = []
        for k, frac in enumerate([0.15, 0.55]):
            url = f"file://{html}#t={t[0] + frac * span:.6g}"
            dom, err = browser.dom(url)
            at = attrs(dom)
            errs = console_errors(err)
            check(at.get("data-status") == "ready" and "data-errors" not in at and not errs,
                  f"{model}: opens at t = {t[0] + frac * span:.4g} without a script error"
                  + (f" ({errs[:2]})" if errs else "") + (f" (status {at.get('data-status')})" if at.get("data-status") != "ready" else ""))
            digests.append(at.get("data-canvas-digest"))
            png = os.path.join(out, f"{model}-{k + 1}.png")
            err = browser.screenshot(url, png)
            errs = console_errors(err)
            check(os.path.exists(png) and os.path.getsize(png) > 5000 and not errs,
                  f"{model}: screenshot {png} ({os.path.getsize(png) if os.path.exists(png) else 0} bytes)")
            if a.docs and k == 0 and model in README_MODELS and os.path.exists(png):
                shutil.copy(png, os.path.join(a.docs, f"screenshot-{model}.png"))
        check(None not in digests and digests[0] != digests[1],
              f"{model}: the drawing changes between the two times (digests {digests})")

    # A run of 1e5 output steps: size and opening time.
    big = os.path.join(out, "slider_crank_bodies-1e5.html")
    sim = run([a.pfaff, "simulate", "slider_crank_bodies", "--t-end", "20", "--samples", "100000",
               "--integrator", "dop853", "--animate", big])
    if check(sim.returncode == 0, "1e5 output steps: simulated"):
        size = os.path.getsize(big)
        check(size < 20e6, f"1e5 output steps: file of {size / 1e6:.2f} MB (limit 20 MB)")
        times = []
        for _ in range(3):
            dom, err = browser.dom(f"file://{big}#t=1")
            at = attrs(dom)
            if at.get("data-status") == "ready":
                times.append(float(at.get("data-open-ms", "inf")))
        best = min(times) if times else float("inf")
        check(best < 2000, f"1e5 output steps: opens in {best:.0f} ms (best of {len(times)}; limit 2000 ms)")

    shutil.rmtree(profile, ignore_errors=True)
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
