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

from .view import CampaignView

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

    def close(self) -> None:
        self.shutdown()
        self.server_close()
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

    def do_GET(self) -> None:  # noqa: N802 - the standard library's name
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
                if url.path == "/api/feasible":
                    query = parse_qs(url.query)
                    return self._json(self.server.view.feasible(query.get("x", [""])[0], query.get("y", [""])[0]))
        except ValueError as exc:
            return self._json({"error": str(exc)}, HTTPStatus.BAD_REQUEST)
        self._json({"error": f"no such page: {url.path}"}, HTTPStatus.NOT_FOUND)

    def do_POST(self) -> None:  # noqa: N802
        self._json({"error": "the dashboard is read-only"}, HTTPStatus.METHOD_NOT_ALLOWED)


def start(store: str | Path, host: str = "127.0.0.1", port: int = 0, config_dir: str | Path | None = None
          ) -> DashboardServer:
    """Serve the dashboard of `store` in a background thread; `server.url` says where, `server.close()` stops it."""
    server = DashboardServer(CampaignView(store, config_dir), host, port)
    threading.Thread(target=server.serve_forever, name="dashboard", daemon=True).start()
    return server


__all__ = ["CampaignView", "DashboardServer", "start"]
