"""``plantmech docs [TOPIC]``: the documentation, shipped inside the package (the
repository's docs/, package data ``plantmech/docs``), so a ``pip install`` user reads the
same pages: without TOPIC the list of pages and where they are; with one, the page."""

from __future__ import annotations

import sys
from pathlib import Path


def docs_dir() -> Path:
    """The installed documentation's directory (Markdown pages and their images)."""
    from importlib import resources

    return Path(str(resources.files("plantmech") / "docs"))


def topics() -> dict[str, str]:
    """{topic: the page's title} for every shipped page, by name."""
    out = {}
    for page in sorted(docs_dir().glob("*.md")):
        with open(page, encoding="utf-8") as fh:
            out[page.stem] = fh.readline().lstrip("# ").strip()
    return out


def _docs(args) -> int:
    from plantmech.typos import did_you_mean

    pages = topics()
    if not pages:
        print(f"error: no documentation found in {docs_dir()} (a broken install: reinstall "
              "plantmech)", file=sys.stderr)
        return 2
    if args.topic is None:
        print(f"plantmech documentation ({docs_dir()}); 'plantmech docs TOPIC' prints one:")
        width = max(map(len, pages))
        for name, title in pages.items():
            print(f"  {name:<{width}}  {title}")
        return 0
    topic = args.topic.removesuffix(".md")
    if topic not in pages:
        print(f"error: TOPIC: no page {args.topic!r}{did_you_mean(topic, pages)}; pages: "
              + ", ".join(pages), file=sys.stderr)
        return 2
    print((docs_dir() / f"{topic}.md").read_text(encoding="utf-8"), end="")
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "docs", help="the documentation (shipped with the package): the pages, or one",
        description="Print a documentation page (Markdown), or without TOPIC list the "
        "pages and the directory they are installed in (images beside them).")
    p.add_argument("topic", nargs="?", default=None,
                   help="page name, e.g. design-file, manufacturing, optimization")
    p.set_defaults(func=_docs)
