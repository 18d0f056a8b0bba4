"""``plantmech app``: the subcommand's input errors and a lean ``plantmech --help``."""

from __future__ import annotations

import subprocess
import sys

import pytest

from plantmech.interfaces.cli import main


def test_help_does_not_import_the_server():
    code = ("import sys; from plantmech.interfaces.cli import build_parser; build_parser(); "
            "print('fastapi' in sys.modules, 'uvicorn' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "False"]


def test_missing_design_file_is_exit_2(tmp_path, capsys):
    assert main(["app", str(tmp_path / "nope.toml"), "--no-browser"]) == 2
    assert "no such design file" in capsys.readouterr().err


def test_invalid_design_file_names_the_field(tmp_path, capsys):
    p = tmp_path / "bad.toml"
    p.write_text('mechanism = "rice_transplanter"\n', encoding="utf-8")
    assert main(["app", str(p), "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "field 'carrier'" in err
    assert p.read_text(encoding="utf-8") == 'mechanism = "rice_transplanter"\n'


@pytest.mark.parametrize("port", ["0", "70000", "abc"])
def test_bad_port_is_exit_2(port, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["app", "--port", port, "--no-browser"])
    assert exc.value.code == 2
    assert "port" in capsys.readouterr().err


@pytest.mark.parametrize("workers", ["-1", "two", "65"])
def test_bad_workers_is_exit_2(workers, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["app", "--workers", workers, "--no-browser"])
    assert exc.value.code == 2
    assert "--workers" in capsys.readouterr().err


def test_only_loopback_hosts():
    with pytest.raises(SystemExit):
        main(["app", "--host", "0.0.0.0", "--no-browser"])


def test_foreign_host_header_is_refused():
    pytest.importorskip("httpx")
    from fastapi.testclient import TestClient

    from plantmech.app.server import create_app

    with TestClient(create_app(), base_url="http://evil.example") as c:
        assert c.get("/api/examples").status_code == 400
