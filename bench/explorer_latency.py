"""The explorer's speed, as the issue states it: from a parameter change (the alpha slider) to the plots
drawn and to the lit sphere's first image, in headless Chromium (Debian's `chromium`, Playwright).

    .venv/bin/python bench/explorer_latency.py [--moves 8] [--gonio target/release/gonio]

Prints the medians and ranges of the times the page itself records (dataset.plotMs: polar + 3-D + slice;
albedoMs: the albedo curve and white furnace; sphereFirstMs: the first sphere image), each measured from
the slider's input event (the page's 40 ms debounce included). Run by hand; not part of make test."""

import argparse
import shutil
import statistics
import subprocess
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gonio", default=str(ROOT / "target" / "release" / "gonio"))
    ap.add_argument("--moves", type=int, default=8)
    args = ap.parse_args()
    server = subprocess.Popen([args.gonio, "explore", "--port", "0"], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        url = next(w for w in server.stdout.readline().split() if w.startswith("http://"))
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=["--no-sandbox"])
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            page.goto(url)
            page.wait_for_function("(d => d.plotToken && d.albedoToken && d.sphereToken)(document.querySelector('.gx').dataset)", timeout=30000)
            time.sleep(3)
            keys = ("plotToken", "albedoToken", "sphereToken")
            times = {"polar + 3-D + slice": [], "albedo + furnace": [], "first sphere image": []}
            for k in range(args.moves):
                before = page.evaluate(f"{list(keys)}.map(k => document.querySelector('.gx').dataset[k])")
                position = 500 + 211 * k % 250  # distinct values of alpha in [0.03, 0.45] on the log slider (none cached)
                page.evaluate(f"(() => {{ const s = document.querySelector('[data-param=alpha] input[type=range]'); s.value = {position}; s.dispatchEvent(new Event('input')); }})()")
                for key, value in zip(keys, before):
                    page.wait_for_function(f"document.querySelector('.gx').dataset.{key} != '{value}'", timeout=30000)
                d = page.evaluate("Object.assign({}, document.querySelector('.gx').dataset)")
                for name, key in zip(times, ("plotMs", "albedoMs", "sphereFirstMs")):
                    times[name].append(int(d[key]))
                time.sleep(1.5)  # let the refinement passes and the quick verification finish
            browser.close()
        for name, values in times.items():
            print(f"{name:22s} median {statistics.median(values):6.0f} ms   range {min(values)}–{max(values)} ms")
    finally:
        server.kill()
        server.wait()


if __name__ == "__main__":
    main()
