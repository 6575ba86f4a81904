import mimo_social  # noqa: F401  (chooses the headless GL backend before mujoco is imported)

import importlib.util  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "text_infos: the module's tests read the envs' text infos (names, reasons, "
                   "touched parts): envs made in them default to info_text=True")


@pytest.fixture(autouse=True)
def _text_infos_where_marked(request, monkeypatch):
    """Tests of a task's behaviour that read its text infos (``info_text=True``) are marked
    ``text_infos``: every env they make defaults to text infos (an explicit ``info_text`` wins).
    The envs' own default, numeric infos, is tested in tests/core/test_numeric_infos.py and
    by the clients (tests/clients)."""
    if request.node.get_closest_marker("text_infos") is None:
        return
    from mimo_social.core.env import MimoParallelEnv
    made = MimoParallelEnv.__init__

    def init(self, *args, info_text=True, **kwargs):
        made(self, *args, info_text=info_text, **kwargs)
    monkeypatch.setattr(MimoParallelEnv, "__init__", init)


@pytest.fixture
def load_script():
    """``load_script(name)``: the module of ``scripts/<name>.py`` (the research scripts are no
    package; their tests load them by path)."""
    def load(name: str):
        spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    return load
