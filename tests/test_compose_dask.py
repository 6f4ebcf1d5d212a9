"""The compose file's "dask" profile needs no hand edit: the app's start command sends runs to
the dask-scheduler service when its name resolves, to its own threads otherwise, and keeps a
scheduler address given in the environment. The command is run here with stand-ins for
``getent`` (the name lookup) and ``mocapqa`` (which reports the address it was started with)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path
from typing import Any

import pytest
import yaml

COMPOSE = Path(__file__).resolve().parents[1] / "docker-compose.yml"


def _compose() -> dict[str, Any]:
    data = yaml.safe_load(COMPOSE.read_text())
    assert isinstance(data, dict)
    return data


def _start(tmp_path: Path, resolves: bool, given: str = "") -> str:
    """The scheduler the app's command starts ``mocapqa serve`` with ('' for none)."""
    command = _compose()["services"]["app"]["command"]
    assert command[:2] == ["sh", "-c"]
    script = command[2].replace("$$", "$")  # compose's escape of a literal $
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    lookup = bin_dir / "getent"
    lookup.write_text(
        '#!/bin/sh\n[ "$1 $2" = "hosts dask-scheduler" ] && '
        + ("echo '172.18.0.3 dask-scheduler'; exit 0\n" if resolves else "exit 2\n")
    )
    report = tmp_path / "serve.txt"
    app = bin_dir / "mocapqa"
    app.write_text(
        "#!/bin/sh\n"
        'case "$1" in\n'
        "  users) echo admin ;;\n"
        f'  serve) printf "%s" "$MOCAPQA_DASK_SCHEDULER" > {report} ;;\n'
        "esac\n"
    )
    for tool in (lookup, app):
        tool.chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    env["MOCAPQA_DASK_SCHEDULER"] = given
    done = subprocess.run(["sh", "-c", script], env=env, capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    assert "runs go to:" in done.stderr
    return report.read_text()


def _scheduler_port() -> str:
    command = _compose()["services"]["dask-scheduler"]["command"]
    return str(command[command.index("--port") + 1])


def test_profile_up_sends_runs_to_the_scheduler_service(tmp_path: Path) -> None:
    assert _start(tmp_path, resolves=True) == f"tcp://dask-scheduler:{_scheduler_port()}"


def test_profile_off_runs_on_the_apps_threads(tmp_path: Path) -> None:
    assert _start(tmp_path, resolves=False) == ""


@pytest.mark.parametrize("resolves", [True, False])
def test_a_scheduler_given_in_the_environment_wins(tmp_path: Path, resolves: bool) -> None:
    given = "tcp://scheduler.cluster.example:8786"
    assert _start(tmp_path, resolves=resolves, given=given) == given


def test_app_waits_for_the_scheduler_only_when_the_profile_starts_it() -> None:
    services = _compose()["services"]
    needs = services["app"]["depends_on"]["dask-scheduler"]
    assert needs == {"condition": "service_healthy", "required": False}
    assert services["dask-scheduler"]["profiles"] == ["dask"]
    assert "healthcheck" in services["dask-scheduler"]
    assert "profiles" not in services["app"]
    # Workers reach the same scheduler and share the app's data folder.
    worker = services["dask-worker"]
    assert f"tcp://dask-scheduler:{_scheduler_port()}" in worker["command"]
    assert "mocapqa-data:/data" in worker["volumes"]
    assert "mocapqa-data:/data" in services["app"]["volumes"]
