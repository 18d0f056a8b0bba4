"""``plantmech app [DESIGN.toml] [--port N] [--no-browser] [--workers N]``: the interactive app.

A local server (FastAPI + uvicorn) bound to 127.0.0.1 serves one page for both
mechanisms; the design file, if given, is opened in it and never written. Exit status:
0 after a clean stop (Ctrl-C), 2 invalid input (the design file, or a port in use).
"""

from __future__ import annotations

import sys


def _run(args) -> int:
    from pathlib import Path

    from plantmech.extras import refused

    if refused("app", "'plantmech app'"):
        return 2

    from plantmech.design import DesignError

    initial = Path(args.design) if args.design else None
    try:
        import uvicorn

        from plantmech.app.server import create_app
        app = create_app(initial, workers=args.workers, prewarm=True)
    except DesignError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    import socket

    with socket.socket() as s:  # a clear message instead of uvicorn's traceback
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
        try:
            s.bind((args.host, args.port))
        except OSError as exc:
            print(f"error: option --port: cannot listen on {args.host}:{args.port} ({exc})",
                  file=sys.stderr)
            return 2
    url = f"http://{args.host}:{args.port}/"
    print(f"plantmech app on {url} (Ctrl-C to stop)")
    if not args.no_browser:
        import threading
        import webbrowser

        threading.Timer(1.0, lambda: webbrowser.open(url)).start()
    from plantmech.app.server import MAX_BODY_BYTES

    # the drag stream's answers are ~10^5 bytes on loopback: compressing them costs more
    # than sending them (measured in chromium, docs/app-performance.md)
    from plantmech.outputs import signals

    try:
        uvicorn.run(app, host=args.host, port=args.port, log_level="warning",
                    ws_per_message_deflate=False, ws_max_size=MAX_BODY_BYTES + 1024)
    except KeyboardInterrupt:  # uvicorn stops on the signal, then raises it again
        pass
    # a signal is how the app is stopped (the server has shut down and ended its tasks):
    # exit 0, not "interrupted ... nothing written" and 130 as for a command that writes
    got = signals.consume()
    print("plantmech app stopped" + (f" ({signals.NAMES.get(got, got)})" if got else ""))
    return 0


def register(subparsers) -> None:
    from plantmech.interfaces.cli import _number

    p = subparsers.add_parser("app", help="interactive design app in the browser "
                              "(local server on 127.0.0.1; needs plantmech[app])")
    p.add_argument("design", nargs="?", help="design file (TOML) to open; never overwritten")
    p.add_argument("--port", type=_number(int, 1, strict=False, maximum=65535), default=8765,
                   help="port on 127.0.0.1 (1-65535, default 8765)")
    p.add_argument("--host", default="127.0.0.1", choices=("127.0.0.1", "localhost"),
                   help="loopback only")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument("--workers", type=_number(int, 0, strict=False, maximum=64), default=None,
                   help="processes computing edits (default: one per usable core; 0: in the "
                   "server's own threads)")
    p.set_defaults(func=_run)
