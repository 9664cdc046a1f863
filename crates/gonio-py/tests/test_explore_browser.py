"""The explorer page in a real browser: `gonio explore` started on a free port, driven by Playwright in
headless Chromium (Debian's `chromium`; Playwright's own browser download is not used). Skips, saying why,
where there is no browser, no Playwright or no built CLI.

Load the page, pick roughconductor, move the alpha slider: the plot data and the sphere image change and
the lobe's peak stays at the mirror direction; add a measured file and fit it; type a bad value and see
the CLI's message next to the field. With GONIO_SCREENSHOTS=DIR the states are saved as PNG files there
(the gallery's explorer pictures: docs/gallery/make_gallery.sh)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
CLI = ROOT / "target" / "release" / "gonio"
RGL = ROOT.parent / "shared" / "data" / "rgl"
CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)

playwright = pytest.importorskip("playwright.sync_api", reason="the browser test needs Playwright (pip install playwright)")
pytestmark = [
    pytest.mark.skipif(CHROMIUM is None, reason="no Chromium here (apt-get install chromium)"),
    pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)"),
]
SHOTS = os.environ.get("GONIO_SCREENSHOTS")


@pytest.fixture(scope="module")
def server():
    args = [str(CLI), "explore", "--port", "0"] + (["--data", str(RGL)] if RGL.is_dir() else [])
    proc = subprocess.Popen(args, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    url = next(w for w in line.split() if w.startswith("http://"))
    yield url
    proc.kill()
    proc.wait()


@pytest.fixture(scope="module")
def page(server):
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        errors = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(server)
        page.wait_for_function("document.querySelector('.gx') && document.querySelector('.gx').dataset.plotToken", timeout=30000)
        yield page
        assert not errors, errors
        browser.close()


def shot(page, name):
    if SHOTS:
        Path(SHOTS).mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(Path(SHOTS) / f"explorer_{name}.png"))


KEYS = ("plotToken", "albedoToken", "sphereToken")


def tokens(page):
    """The counters of the plots (polar, 3-D, slice), the albedo and the sphere images drawn so far."""
    return page.evaluate(f"{list(KEYS)}.map(k => document.querySelector('.gx').dataset[k])")


def settle(page, before, timeout=60000):
    """Wait for the plots, the albedo and the first sphere image asked for after `before` (from `tokens`)."""
    for key, value in zip(KEYS, before):
        page.wait_for_function(f"document.querySelector('.gx').dataset.{key} != '{value}'", timeout=timeout)


def state(page):
    return page.evaluate("""() => {
        const app = document.querySelector('.gx').gxExplorer;
        const p = app.data.polar.list[app.data.polar.shown.findIndex(s => s.i === app.state.sel)];
        const img = document.querySelector('.gx-sphere');
        const c = document.createElement('canvas'); c.width = 64; c.height = 64;
        const g = c.getContext('2d'); g.drawImage(img, 0, 0, 64, 64);
        const px = Array.from(g.getImageData(0, 0, 64, 64).data).filter((_, k) => k % 4 !== 3);
        return { angles: p.angles, incidence: p.incidence, theta_o: app.state.theta_o, sphere: px };
    }""")


def set_slider(page, param, position):
    page.evaluate("""([param, v]) => { const s = document.querySelector(`[data-param=${param}] input[type=range]`);
        s.value = v; s.dispatchEvent(new Event('input')); }""", [param, position])


def peak_angle(s):
    k = max(range(len(s["incidence"])), key=lambda i: s["incidence"][i] or 0.0)
    return s["angles"][k]


def test_alpha_slider_changes_plots_and_sphere_and_keeps_the_mirror_peak(page):
    t = tokens(page)
    page.select_option(".gx-form select", "roughconductor")
    settle(page, t)
    t = tokens(page)
    set_slider(page, "alpha", 300)  # a log slider over [1e-4, 10]: α ≈ 0.003, sharp
    settle(page, t)
    page.wait_for_timeout(500)
    before = state(page)
    shot(page, "1_sharp")
    t = tokens(page)
    set_slider(page, "alpha", 700)  # α ≈ 0.32, glossy (near α = 1 the Beckmann lobe turns back towards the viewer)
    settle(page, t)
    page.wait_for_timeout(500)
    after = state(page)
    shot(page, "2_rough")
    assert after["incidence"] != before["incidence"], "the plot data changed"
    change = sum(abs(a - b) for a, b in zip(after["sphere"], before["sphere"])) / len(after["sphere"])
    assert change > 2.0, f"the sphere image changed (mean difference {change:.2f} of 255)"
    for s in (before, after):
        assert abs(peak_angle(s) + s["theta_o"]) <= 2.0, f"lobe peak at {peak_angle(s)}°, mirror at {-s['theta_o']}°"


def test_phi_d_slider_moves_the_slice_only(page):
    t = tokens(page)
    page.select_option(".gx-form select", "roughconductor")
    settle(page, t)
    read = "() => { const a = document.querySelector('.gx').gxExplorer; return [a.data.slice.d, a.data.polar.list[0]]; }"
    slice_before, polar_before = page.evaluate(read)
    t = tokens(page)
    page.evaluate("() => { const s = document.querySelector('.gx-phi-d'); s.value = 30; s.dispatchEvent(new Event('input')); }")
    settle(page, t)
    slice_after, polar_after = page.evaluate(read)
    assert (slice_before["phi_d"], slice_after["phi_d"]) == (90, 30)
    assert slice_after["values"] != slice_before["values"], "the slice at φd = 30° differs from φd = 90°"
    assert polar_after == polar_before, "the polar plot does not depend on φd"
    assert page.evaluate("() => JSON.parse(decodeURIComponent(location.hash.slice(1))).phi_d") == 30, "φd is in the URL's state"


def test_bad_value_shows_the_clis_message_next_to_the_field(page):
    page.fill("[data-param=alpha] input[type=number]", "20")
    page.press("[data-param=alpha] input[type=number]", "Enter")
    page.dispatch_event("[data-param=alpha] input[type=number]", "change")
    page.wait_for_function("document.querySelector('[data-param=alpha] .gx-field-error').textContent.length > 0", timeout=30000)
    message = page.inner_text("[data-param=alpha] .gx-field-error")
    assert message == "$.alpha: parameter `alpha` of `roughconductor` must be a number in [0.0001, 10], got 20"
    shot(page, "3_bad_value")
    page.click("[data-param=alpha] button")  # back to the default


@pytest.mark.skipif(not (RGL / "paper_white_rgb.bsdf").exists(), reason="no RGL measurement in ../shared/data/rgl")
def test_measured_file_and_its_fit_are_overlaid(page):
    t = tokens(page)
    page.select_option(".gx-side .gx-row:nth-of-type(2) select", "paper_white_rgb.bsdf")
    page.click(".gx-side .gx-row:nth-of-type(2) button")
    settle(page, t)
    assert page.evaluate("document.querySelector('.gx').gxExplorer.layer.spec.type") == "measured"
    count = page.evaluate("document.querySelector('.gx').gxExplorer.state.layers.length")
    page.select_option(".gx-side .gx-row:has(> button:text('fit')) select", "ggx+diffuse")
    page.click(".gx-side button:text('fit')")
    page.wait_for_function(f"document.querySelector('.gx').gxExplorer.state.layers.length > {count}", timeout=120000)
    fitted = page.evaluate("document.querySelector('.gx').gxExplorer.layer")
    assert fitted["label"].startswith("fit ggx+diffuse")
    # The measured material and its twin are drawn together (the polar plot shows every model).
    page.wait_for_function(f"document.querySelector('.gx').gxExplorer.data.polar.list.length === {count + 1}", timeout=60000)
    page.wait_for_function(f"(document.querySelector('.gx').gxExplorer.data.albedo || {{list: []}}).list.length === {count + 1}", timeout=120000)
    assert page.inner_text(".gx-error") == ""
    page.wait_for_timeout(1000)
    shot(page, "4_measured_and_fit")


def test_widget_entry_point_runs_the_same_explorer(page, server):
    """anywidget's render() with a stand-in for the widget model whose messages the server answers, as the
    Python side answers them in Jupyter (the JS glue of gonio.explore, in a real browser)."""
    result = page.evaluate("""async () => {
        const widget = (await import('/explorer.js')).default;
        const handlers = {};
        const values = { state: JSON.stringify({ layers: [{ spec: { type: 'diffuse', reflectance: 0.5 }, colour: '#d62728', visible: true }], sel: 0 }) };
        const model = {
            get: (k) => values[k], set: (k, v) => { values[k] = v; }, save_changes: () => {},
            on: (name, f) => { handlers[name] = f; },
            send: async (msg) => {
                const r = await fetch(msg.path + '?' + msg.query);
                const body = new DataView(await r.arrayBuffer());
                handlers['msg:custom']({ id: msg.id, status: r.status, type: r.headers.get('content-type') }, [body]);
            },
        };
        const el = document.createElement('div');
        document.body.append(el);
        widget.render({ model, el });
        const root = el.querySelector('div');
        for (let k = 0; k < 300 && !(root.dataset.plotToken && root.gxExplorer.data.polar); k++) await new Promise((r) => setTimeout(r, 100));
        const app = root.gxExplorer;
        const spec = JSON.parse(values.spec || 'null');
        el.remove();
        return { type: app.layer.spec.type, polar: app.data.polar.list[0].incidence.length, spec };
    }""")
    assert result["type"] == "diffuse"
    assert result["polar"] == 721
    assert result["spec"] == {"type": "diffuse", "reflectance": 0.5}, "the widget reports the selected model to Python"


def test_url_encodes_the_state(page, server):
    """A shared address shows the same models and view."""
    import json
    from urllib.parse import quote

    state = {"layers": [{"spec": {"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}, "colour": "#2ca02c", "visible": True},
                        {"spec": {"type": "roughplastic", "alpha": 0.05}, "colour": "#d62728", "visible": True}],
             "sel": 1, "theta_o": 50, "light": "furnace"}
    context = page.context.browser.new_context(viewport={"width": 1400, "height": 1000})
    other = context.new_page()
    other.goto(server + "#" + quote(json.dumps(state)))
    other.wait_for_function("document.querySelector('.gx') && document.querySelector('.gx').dataset.plotToken", timeout=30000)
    app = other.evaluate("(({ state, data }) => ({ state, n: data.polar.list.length, theta: data.polar.list[0].theta_o }))(document.querySelector('.gx').gxExplorer)")
    assert [l["spec"]["type"] for l in app["state"]["layers"]] == ["diffuse", "roughplastic"]
    assert (app["state"]["sel"], app["state"]["theta_o"], app["state"]["light"], app["n"], app["theta"]) == (1, 50, "furnace", 2, 50)
    assert other.input_value("[data-param=alpha] input[type=number]") == "0.05", "the form shows the selected model"
    context.close()
