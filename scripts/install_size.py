"""Measure what ``pip install`` of plantmech puts in site-packages (issue 33's "the base
install holds at most 600 MB").

Run: ``python scripts/install_size.py [--extras all] [--top 15]``. Builds the wheel of this
checkout, installs it into a new virtualenv in a temporary directory exactly as a user's
``pip install .`` would (pip's defaults: dependencies resolved, bytecode compiled), and prints
the disk space of its site-packages as ``du -sm`` counts it (allocated blocks, MiB),
without the virtualenv's own pip and setuptools (they are there before plantmech is), then
the largest distributions. The virtualenv is removed afterwards. About a minute with the
packages at hand; more when pip downloads them.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: what ``python -m venv`` installs by itself: not plantmech's
VENV_OWN = ("pip", "setuptools", "pkg_resources", "_distutils_hack", "distutils-precedence.pth")
MIB = 1024 * 1024


def disk_bytes(path: Path) -> int:
    """Allocated bytes of ``path`` and everything under it (``du``'s count; links not
    followed)."""
    st = path.lstat()
    total = st.st_blocks * 512
    if path.is_dir() and not path.is_symlink():
        for root, dirs, files in os.walk(path):
            for name in dirs + files:
                total += os.lstat(os.path.join(root, name)).st_blocks * 512
    return total


def _owner(entry: str) -> str:
    """The distribution a top-level site-packages entry belongs to (by name)."""
    name = entry.split("-")[0] if entry.endswith((".dist-info", ".egg-info")) else entry
    name = name.removesuffix(".libs").removesuffix(".py").lower().replace("_", "-")
    return {"pil": "pillow", "mpl-toolkits": "matplotlib"}.get(name, name)


def measure(extras: str | None, top: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="plantmech-size-") as tmp:
        tmp = Path(tmp)
        subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w",
                        str(tmp / "wheels"), str(ROOT)], check=True)
        wheel = next((tmp / "wheels").glob("plantmech-*.whl"))
        subprocess.run([sys.executable, "-m", "venv", str(tmp / "venv")], check=True)
        python = tmp / "venv" / "bin" / "python"
        site = Path(subprocess.run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            check=True, capture_output=True, text=True).stdout.strip())
        before = {p.name for p in site.iterdir()}
        target = f"{wheel}[{extras}]" if extras else str(wheel)
        subprocess.run([str(python), "-m", "pip", "install", "-q", target], check=True)
        sizes: dict[str, int] = {}
        own = 0
        for entry in site.iterdir():
            b = disk_bytes(entry)
            if entry.name in before or entry.name.startswith(VENV_OWN):
                own += b
                continue
            sizes[_owner(entry.name)] = sizes.get(_owner(entry.name), 0) + b
    total = sum(sizes.values())
    return {"extras": extras or "(base)", "site_packages_mib": total / MIB,
            "with_venv_own_mib": (total + own) / MIB,
            "largest": sorted(sizes.items(), key=lambda kv: -kv[1])[:top]}


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--extras", default=None, help="e.g. all, app, studies (default: the base)")
    ap.add_argument("--top", type=int, default=15, help="how many distributions to list")
    args = ap.parse_args(argv)
    r = measure(args.extras, args.top)
    print(f"plantmech{'[' + args.extras + ']' if args.extras else ''}: "
          f"{r['site_packages_mib']:.0f} MB in site-packages (du -sm, MiB, bytecode "
          f"compiled by pip; {r['with_venv_own_mib']:.0f} MB with the virtualenv's own pip "
          "and setuptools)")
    for name, b in r["largest"]:
        print(f"  {b / MIB:7.1f} MB  {name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
