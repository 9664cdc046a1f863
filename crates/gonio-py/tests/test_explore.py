"""gonio.explore: the explorer widget built and driven without a browser — its messages answered by the
extension with the numbers of gonio.lobe_data & co., bad input answered 400 with gonio's own message, and
widget.bsdf following the state the page sets."""

import json
from urllib.parse import urlencode

import numpy as np
import pytest

import gonio

anywidget = pytest.importorskip("anywidget", reason="gonio.explore needs anywidget (pip install anywidget)")

GGX = {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Au"}


def ask(widget, path, **params):
    """Send the widget the message the page sends and return what it answers: (reply fields, body)."""
    sent = []
    widget.send = lambda content, buffers=None: sent.append((content, buffers))
    widget._on_message(widget, {"id": 7, "path": path, "query": urlencode(params)}, [])
    assert len(sent) == 1
    content, buffers = sent[0]
    assert content["id"] == 7
    return content, bytes(buffers[0])


def test_widget_carries_the_page_and_the_model():
    w = gonio.explore(GGX, {"type": "diffuse"}, threads=0)
    assert isinstance(w, anywidget.AnyWidget)
    assert "export default" in w._esm and "export function mount" in w._esm
    assert ".gx" in w._css
    assert w.bsdf.spec == json.dumps(GGX)
    assert [m["type"] for m in w.models] == ["roughconductor", "diffuse"]
    with pytest.raises(gonio.SpecError, match="alpha"):
        gonio.explore({"type": "roughconductor", "alpha": 20})


def test_messages_are_answered_with_gonio_plot_numbers():
    w = gonio.explore(GGX, threads=0)
    reply, body = ask(w, "/api/plot", spec=json.dumps(GGX), kind="polar", theta_o=40)
    assert (reply["status"], reply["type"]) == (200, "application/json")
    polar = json.loads(body)
    lobe = gonio.lobe_data(GGX, 40.0)
    lum = np.array(polar["incidence"], dtype=np.float32)
    np.testing.assert_array_equal(lum, lobe.incidence[:, 3])
    peak = polar["angles"][int(np.argmax(lum))]
    assert abs(peak + 40.0) <= 1.0, "the lobe peaks at the mirror direction"
    reply, body = ask(w, "/api/plot", spec=json.dumps(GGX), kind="albedo")
    albedo = gonio.albedo_data(GGX)
    np.testing.assert_array_equal(np.array(json.loads(body)["albedo"], dtype=np.float32), albedo.albedo[:, 3])
    reply, body = ask(w, "/api/sphere", spec=json.dumps(GGX), light="furnace", size=32)
    assert reply["status"] == 200 and body.startswith(b"\x89PNG")
    models = json.loads(ask(w, "/api/models")[1])
    assert [m["plugin"] for m in models["models"]] == list(gonio.plugins())


def test_bad_input_is_the_clis_message():
    w = gonio.explore(threads=0)
    bad = {"type": "roughconductor", "alpha": 20}
    reply, body = ask(w, "/api/plot", spec=json.dumps(bad), kind="polar")
    assert reply["status"] == 400
    error = json.loads(body)
    with pytest.raises(gonio.SpecError) as expected:
        gonio.load_bsdf(bad)
    assert error["error"] == str(expected.value)
    assert error["param"] == "alpha"
    status, _, _ = w.request("/api/plot", spec="{nope")
    assert status == 400


def test_bsdf_follows_the_state_the_page_sets():
    w = gonio.explore(GGX, threads=0)
    edited = dict(GGX, alpha=0.5)
    # What the page does when the slider moves: it sets `state` and `spec` (the selected model).
    w.state = json.dumps({"layers": [{"spec": edited, "colour": "#1f77b4", "visible": True}], "sel": 0})
    w.spec = json.dumps(edited)
    assert w.bsdf.spec == json.dumps(edited)
    assert w.models == [edited]
    wo = np.array([[0.0, 0.0, 1.0]])
    wi = np.array([[0.3, 0.0, 0.954]])
    wi /= np.linalg.norm(wi)
    np.testing.assert_array_equal(w.bsdf.f(wo, wi), gonio.load_bsdf(edited).f(wo, wi))
