"""A live, read-only, offline web page of a campaign: `gryffin-ros dashboard STORE`, or the planner node's
`dashboard_port` parameter.

The server is the standard library's threading HTTP server (GET only, bound to 127.0.0.1 unless told otherwise):
the page is a few files of this package plus plotly.js from the `plotly` package, so nothing is fetched from the
internet. The page polls `/api/campaign` every two seconds and redraws when the store has changed.
"""

from __future__ import annotations

import json
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlparse

from ..planner.errors import GryffinRosError
from .view import CampaignView, CannotDraw

LOOPBACK = {"127.0.0.1", "localhost", "::1"}

STATIC = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/dashboard.js": ("dashboard.js", "text/javascript; charset=utf-8"),
    "/dashboard.css": ("dashboard.css", "text/css; charset=utf-8"),
}


def _plotly_js() -> bytes:
    return resources.files("plotly").joinpath("package_data/plotly.min.js").read_bytes()


class DashboardServer(ThreadingHTTPServer):
    daemon_threads = True

    def __init__(self, view: CampaignView, host: str = "127.0.0.1", port: int = 0):
        self.view = view
        self.lock = threading.Lock()  # one view computation at a time (the store reader is shared)
        super().__init__((host, port), _Handler)

    @property
    def url(self) -> str:
        host, port = self.server_address[:2]
        return f"http://{host}:{port}/"

    @property
    def loopback(self) -> bool:
        return self.server_address[0] in LOOPBACK

    def close(self) -> None:
        self.shutdown()
        self.server_close()
        with self.lock:  # a request still being answered finishes first
            self.view.close()


class _Handler(BaseHTTPRequestHandler):
    server: DashboardServer

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - quiet: no line per poll
        pass

    def _send(self, status: HTTPStatus, body: bytes, content_type: str, cache: bool = False) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "max-age=3600" if cache else "no-store")
        self.end_headers()
        self.wfile.write(body)

    def _json(self, document: Any, status: HTTPStatus = HTTPStatus.OK) -> None:
        self._send(status, json.dumps(document, allow_nan=False).encode(), "application/json")

    def _host_allowed(self) -> bool:
        """On loopback, only requests addressed to loopback (a page elsewhere that rebinds its own name to 127.0.0.1
        cannot read the campaign)."""
        if not self.server.loopback:
            return True
        host = (self.headers.get("Host") or "").rsplit(":", 1)[0].strip("[]")
        return host in LOOPBACK

    def do_GET(self) -> None:  # noqa: N802 - the standard library's name
        if not self._host_allowed():
            return self._json({"error": "this dashboard answers requests to 127.0.0.1 only"}, HTTPStatus.FORBIDDEN)
        url = urlparse(self.path)
        if url.path in STATIC:
            name, content_type = STATIC[url.path]
            body = resources.files(__package__).joinpath("static", name).read_bytes()
            return self._send(HTTPStatus.OK, body, content_type)
        if url.path == "/plotly.min.js":
            return self._send(HTTPStatus.OK, _plotly_js(), "text/javascript; charset=utf-8", cache=True)
        try:
            with self.server.lock:
                if url.path == "/api/campaign":
                    return self._json(self.server.view.campaign())
                if url.path == "/api/molecule.svg":
                    query = parse_qs(url.query)
                    svg = self.server.view.molecule_svg(query.get("parameter", [""])[0], query.get("option", [""])[0])
                    return self._send(HTTPStatus.OK, svg.encode(), "image/svg+xml", cache=True)
                if url.path == "/api/feasible":
                    query = parse_qs(url.query)
                    return self._json(self.server.view.feasible(query.get("x", [""])[0], query.get("y", [""])[0]))
        except ValueError as exc:
            return self._json({"error": str(exc)}, HTTPStatus.BAD_REQUEST)
        except CannotDraw as exc:  # RDKit is not installed: the page shows the SMILES alone
            return self._json({"error": str(exc)}, HTTPStatus.NOT_IMPLEMENTED)
        except Exception as exc:  # noqa: BLE001 - the page shows it; the server keeps serving
            return self._json({"error": f"{type(exc).__name__}: {exc}"}, HTTPStatus.INTERNAL_SERVER_ERROR)
        self._json({"error": f"no such page: {url.path}"}, HTTPStatus.NOT_FOUND)

    def do_POST(self) -> None:  # noqa: N802
        self._json({"error": "the dashboard is read-only"}, HTTPStatus.METHOD_NOT_ALLOWED)


def start(store: str | Path, host: str = "127.0.0.1", port: int = 0, config_dir: str | Path | None = None
          ) -> DashboardServer:
    """Serve the dashboard of `store` in a background thread; `server.url` says where, `server.close()` stops it.
    Any other `host` than loopback makes the read-only page reachable from the network, without authentication.
    Raises GryffinRosError (StoreError) for a store that is not there, or a port that cannot be served."""
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise GryffinRosError(f"dashboard port must be 0..65535 (0: any free port), got {port!r}")
    view = CampaignView(store, config_dir)
    try:
        server = DashboardServer(view, host, port)
    except OSError as exc:
        view.close()
        raise GryffinRosError(f"the dashboard cannot serve on {host}:{port}: {exc.strerror or exc}") from None
    threading.Thread(target=server.serve_forever, name="dashboard", daemon=True).start()
    return server


__all__ = ["CampaignView", "DashboardServer", "start"]
