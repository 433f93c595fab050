#!/usr/bin/env python3
"""Static HTTP server for the skybake runtime viewer (python3 stdlib only).

Serves, on 127.0.0.1 only (never another interface):
    /                   the viewer page: the repository's viewer/ folder (--root overrides)
    /outputs/           a bake's outputs folder (--outputs, default outputs/)
    /vendor/ktx-parse/  .tools/node_modules/ktx-parse/dist/ (installed by scripts/setup), the
                        KTX2 reader the viewer imports
with the MIME types a browser needs for ES modules and binary LUTs (.js/.mjs text/javascript,
.glsl text/plain, .ktx2 application/octet-stream, ...), no caching (a rebake shows on reload),
/favicon.ico answered 204 when the page has none (else every page load logs a 404 console error),
and no way out of those folders ('..' segments, also percent-encoded, and symlinks that lead
outside a folder answer 404).

    python3 scripts/view_server.py [--outputs DIR] [--root DIR] [--port N] [--print-port] [--quiet]

--port 0 (the default) takes a free port. The first stdout line is the URL
(http://127.0.0.1:PORT/), or with --print-port the bare port number, so a test can start the
server with --port 0 --print-port and read the port from the first line; it is flushed at once.
Serves until Ctrl-C or SIGTERM (exit 0). A missing folder is an error (message, exit 1) before
anything listens. scripts/view is the command-line front end.
"""

import argparse
import http.server
import os
import posixpath
import signal
import sys
import urllib.parse

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Extension -> Content-Type. Module scripts must be served as JavaScript (browsers refuse
# import of anything else); .ktx2/.exr are opaque bytes the viewer parses itself.
MIME_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".mjs": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
    ".glsl": "text/plain; charset=utf-8",
    ".txt": "text/plain; charset=utf-8",
    ".md": "text/plain; charset=utf-8",
    ".csv": "text/plain; charset=utf-8",
    ".yaml": "text/plain; charset=utf-8",
    ".json": "application/json",
    ".map": "application/json",
    ".ktx2": "application/octet-stream",
    ".dds": "application/octet-stream",
    ".exr": "application/octet-stream",
    ".bin": "application/octet-stream",
    ".png": "image/png",
    ".svg": "image/svg+xml",
    ".ico": "image/x-icon",
}


def make_handler(mounts, quiet):
    """A request handler class serving `mounts`: (url prefix, folder) pairs, longest first."""

    class Handler(http.server.SimpleHTTPRequestHandler):
        extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, **MIME_TYPES,
                          "": "application/octet-stream"}

        def resolve(self, url_path):
            """The file a URL path names, or None when it lies outside every mounted folder."""
            path = urllib.parse.unquote(url_path.split("?", 1)[0].split("#", 1)[0])
            if "\0" in path or not path.startswith("/"):
                return None
            # Reject '..' before any normalisation so that /outputs/../x cannot become /x.
            segments = path.split("/")
            if ".." in segments:
                return None
            for prefix, folder in mounts:
                bare = prefix.rstrip("/")
                if path == bare or path.startswith(prefix):
                    rest = path[len(bare):].lstrip("/")
                    full = os.path.join(folder, *[s for s in rest.split("/") if s not in ("", ".")])
                    # Symlinks inside a served folder may not lead out of it.
                    real = os.path.realpath(full)
                    if real != folder and not real.startswith(folder + os.sep):
                        return None
                    if path.endswith("/") and not full.endswith(os.sep):
                        full += os.sep  # keeps SimpleHTTPRequestHandler's directory logic
                    return full
            return None

        def translate_path(self, path):
            # Called by SimpleHTTPRequestHandler.send_head after do_GET/do_HEAD refused what
            # resolve() rejects; "" (opening it fails) answers 404 should one slip through.
            full = self.resolve(path)
            return full if full is not None else ""

        def end_headers(self):
            self.send_header("Cache-Control", "no-store")
            super().end_headers()

        def do_GET(self):
            full = self.resolve(self.path)
            if full is None:
                self.send_error(404, "Not found")
                return
            if self.path.split("?", 1)[0] == "/favicon.ico" and not os.path.isfile(full):
                # Browsers ask for it unprompted; a 404 would be a console error in every test.
                self.send_response(204)
                self.end_headers()
                return
            super().do_GET()

        def do_HEAD(self):
            if self.resolve(self.path) is None:
                self.send_error(404, "Not found")
                return
            super().do_HEAD()

        def log_message(self, format, *args):
            if not quiet:
                super().log_message(format, *args)

    return Handler


def main():
    parser = argparse.ArgumentParser(
        prog="view_server.py",
        description="Serve the skybake viewer (/), a bake's outputs (/outputs/) and ktx-parse "
                    "(/vendor/ktx-parse/) on 127.0.0.1.")
    parser.add_argument("--outputs", default=os.path.join(REPO, "outputs"),
                        help="the bake's outputs folder, served at /outputs/ (default: outputs/)")
    parser.add_argument("--root", default=os.path.join(REPO, "viewer"),
                        help="the folder served at / (default: viewer/)")
    parser.add_argument("--port", type=int, default=0,
                        help="TCP port on 127.0.0.1; 0 (default) takes a free one")
    parser.add_argument("--print-port", action="store_true",
                        help="print the bare port number as the first stdout line (for tests)")
    parser.add_argument("--quiet", action="store_true", help="do not log requests to stderr")
    args = parser.parse_args()

    vendor = os.path.join(REPO, ".tools", "node_modules", "ktx-parse", "dist")
    folders = [("outputs folder", args.outputs, "run scripts/bake first, or name another"),
               ("viewer folder", args.root, "the page served at /"),
               ("ktx-parse", vendor, "run scripts/setup")]
    for what, folder, hint in folders:
        if not os.path.isdir(folder):
            print(f"view_server: {what} '{folder}' does not exist or is not a folder ({hint})",
                  file=sys.stderr)
            return 1
    if not 0 <= args.port <= 65535:
        print(f"view_server: --port {args.port}: expected 0..65535", file=sys.stderr)
        return 2

    # Longest prefix first so /outputs/ and /vendor/ktx-parse/ win over /.
    mounts = [("/vendor/ktx-parse/", os.path.realpath(vendor)),
              ("/outputs/", os.path.realpath(args.outputs)),
              ("/", os.path.realpath(args.root))]
    try:
        server = http.server.ThreadingHTTPServer(("127.0.0.1", args.port),
                                                 make_handler(mounts, args.quiet))
    except OSError as e:
        print(f"view_server: cannot listen on 127.0.0.1:{args.port}: {e.strerror}", file=sys.stderr)
        return 1
    server.daemon_threads = True
    port = server.server_address[1]
    url = f"http://127.0.0.1:{port}/"
    if args.print_port:
        print(port, flush=True)
    print(url, flush=True)
    if not args.print_port:
        print(f"view_server: viewer {mounts[2][1]} at /, outputs {mounts[1][1]} at /outputs/; "
              "Ctrl-C to stop", file=sys.stderr, flush=True)

    # SIGTERM (a test tearing the server down) ends the loop like Ctrl-C does.
    def on_sigterm(signum, frame):
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, on_sigterm)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
