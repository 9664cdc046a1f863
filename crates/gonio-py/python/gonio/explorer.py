"""``gonio.explore``: the explorer of ``gonio explore`` as a Jupyter widget.

The widget runs the page's own JavaScript module (``web/explorer.js`` of the repository, embedded in the
extension) with anywidget; its requests travel as widget messages and are answered in the extension by
the same Rust code as the command line's server (``gonio::explore``), so a notebook and the browser show
the same numbers. No server, no port.

>>> w = gonio.explore({"type": "roughconductor", "alpha": 0.2})   # doctest: +SKIP
>>> w                                                               # doctest: +SKIP
>>> w.bsdf            # the selected model as edited in the widget   # doctest: +SKIP
"""

from __future__ import annotations

import functools
import json
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Tuple, Union
from urllib.parse import urlencode

from . import _gonio

_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"]


def _spec_text(model: Any) -> str:
    """A model (``Bsdf`` built from JSON, dict or JSON string) as the JSON text the explorer takes."""
    if isinstance(model, _gonio.Bsdf):
        model = model.spec
    if isinstance(model, Mapping):
        model = json.dumps(model)
    if not isinstance(model, str) or not model.lstrip().startswith("{"):
        raise ValueError("gonio.explore takes models as dicts, JSON strings or Bsdf objects built from them")
    _gonio.from_json(model)  # the model's own error, as the CLI gives it
    return model


@functools.lru_cache(maxsize=None)
def _widget_class() -> type:
    """The widget's class, defined on first use: anywidget brings in ipywidgets and IPython (~0.15 s), which
    ``import gonio`` should not pay for. Raises ImportError naming the package when anywidget is missing."""
    try:
        import anywidget
        import traitlets
    except ImportError as e:
        raise ImportError("gonio.explore needs anywidget: pip install anywidget") from e
    js, css = _gonio._explorer_page()

    class ExplorerWidget(anywidget.AnyWidget):
        """The explorer in a notebook. ``state`` is the page's state (JSON: the models, their colours, the
        view), ``spec`` the selected model's JSON; ``bsdf`` builds it. ``request`` asks what the page asks."""

        _esm = js
        _css = css
        state = traitlets.Unicode("").tag(sync=True)
        spec = traitlets.Unicode("").tag(sync=True)

        def __init__(self, models: Sequence[Any], *, data: Optional[Union[str, Path]] = None,
                     environment: Optional[Union[str, Path]] = None, threads: int = 2, **kwargs: Any) -> None:
            specs = [_spec_text(m) for m in models] or ['{"type": "roughconductor", "distribution": "ggx", "alpha": 0.2}']
            layers = [{"spec": json.loads(s), "colour": _COLOURS[i % len(_COLOURS)], "visible": True} for i, s in enumerate(specs)]
            super().__init__(state=json.dumps({"layers": layers, "sel": 0}), spec=specs[0], **kwargs)
            self._explorer = _gonio.Explorer(None if data is None else str(data), [],
                                             None if environment is None else str(environment), specs)
            # Renders and checks take up to seconds: answer in threads so that the kernel stays responsive
            # (the extension releases the GIL while it computes).
            self._pool = ThreadPoolExecutor(max_workers=threads) if threads > 0 else None
            self.on_msg(self._on_message)

        @property
        def bsdf(self) -> "_gonio.Bsdf":
            """The selected model as edited in the widget."""
            return _gonio.from_json(self.spec)

        @property
        def models(self) -> list:
            """Every model shown, as dicts (Mitsuba's dictionary form)."""
            return [layer["spec"] for layer in json.loads(self.state)["layers"]]

        def request(self, path: str, **params: Any) -> Tuple[int, str, bytes]:
            """What the page asks: ``request("/api/plot", spec=..., kind="polar")`` → (status, type, body)."""
            return self._explorer.handle(path, urlencode({k: str(v) for k, v in params.items()}))

        def _answer(self, content: Mapping[str, Any]) -> None:
            status, content_type, body = self._explorer.handle(str(content.get("path", "")), str(content.get("query", "")))
            self.send({"id": content.get("id"), "status": status, "type": content_type}, [body])

        def _on_message(self, _widget: Any, content: Any, _buffers: Any) -> None:
            if not isinstance(content, Mapping) or "path" not in content:
                return
            if self._pool is None:
                self._answer(content)
            else:
                self._pool.submit(self._answer, content)

    return ExplorerWidget


def explore(*models: Any, data: Optional[Union[str, Path]] = None, environment: Optional[Union[str, Path]] = None,
            threads: int = 2) -> Any:
    """Look at models in a notebook: polar and 3-D lobes, the θh × θd slice, the albedo and white furnace,
    a path-traced lit sphere and the verification verdict, updating as the sliders move.

    ``models`` are dicts, JSON strings or ``Bsdf`` objects built from them (none: a rough conductor);
    ``data`` a folder of measured files (.binary, .bsdf) the widget may load; ``environment`` an environment
    map for the lit sphere (else the built-in sky). Returns the widget; ``widget.bsdf`` is the selected
    model as edited. Needs ``anywidget`` (``pip install anywidget``).
    """
    return _widget_class()(models, data=data, environment=environment, threads=threads)
