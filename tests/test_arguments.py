"""One parser for every command's key=value arguments (replication/arguments.py): typed settings declared per
command, ``a,b`` lists read once, the rest handed to Hydra, anything else one line naming the known keys."""

from dataclasses import dataclass

import pytest

from replication.arguments import names, parse, read
from replication.errors import ConfigError


@dataclass(frozen=True)
class Settings:
    experiment: tuple[str, ...] | None = None
    pdf: bool = True
    n_jobs: int = 2
    source: str = "store"


def test_settings_are_typed_with_their_defaults_and_the_rest_handed_on():
    settings, handed = parse(["experiment=a,b", "pdf=FALSE", "n_jobs=4", "store=s", "experiment.runs.quick=2",
                              "source=record", "n_jobs=1"], Settings, "cmd", ("store", "experiment."))
    assert settings == Settings(("a", "b"), False, 1, "record")  # the later n_jobs over the earlier
    assert handed == ["store=s", "experiment.runs.quick=2"]
    assert parse([], Settings, "cmd") == (Settings(), [])
    assert parse(["~experiment.report", "x=1"], Settings, "cmd", ("*",))[1] == ["~experiment.report", "x=1"]
    with pytest.raises(ConfigError, match="arguments are key=value; got quick"):  # Hydra's own: ~key alone
        parse(["quick"], Settings, "cmd", ("*",))
    assert names("gps_qmcpf,hspf") == ("gps_qmcpf", "hspf") and names("hspf") == ("hspf",)


@pytest.mark.parametrize("argv, said", [
    (["pdf=maybe"], "pdf must be true or false, got 'maybe'"),
    (["n_jobs=two"], "n_jobs must be an integer, got 'two'"),
    (["quick"], "arguments are key=value; got quick"),
    (["reports=r"], "unknown option 'reports' for cmd; known: experiment=, pdf=, n_jobs=, source=, store=, "
                    "experiment.<key>="),
])
def test_a_bad_argument_is_one_line_naming_the_known_keys(argv, said, capsys):
    with pytest.raises(ConfigError) as error:
        parse(argv, Settings, "cmd", ("store", "experiment."))
    assert str(error.value) == said
    with pytest.raises(SystemExit) as stopped:
        read(argv, Settings, "cmd", ("store", "experiment."))
    assert stopped.value.code == 2 and capsys.readouterr().err == f"error: {said}\n"


@pytest.mark.parametrize("module, argv, said", [
    ("replication.scenes.__main__", ["experiment=bis_pf", "boxes=yes"], "boxes must be true or false"),
    ("replication.report.pdf", ["report=x"], "unknown option 'report' for python -m replication.report.pdf"),
    ("replication.report.calibration", ["replications=many"], "replications must be an integer"),
    ("replication.record.__main__", ["experiment=nope"], "unknown experiment 'nope'"),
    ("replication.record.__main__", ["scale=quick"], "unknown option 'scale' for record; known: experiment=, store="),
    ("replication.record.verify", ["n_jobs=0"], "verify: n_jobs must be a positive integer"),
    ("replication.record.verify", ["cheap=true"], "unknown option 'cheap' for verify; known: N=, experiment="),
    ("replication.report.__main__", ["experiment=hspf,nope"], "unknown experiment 'nope'"),
    ("replication.report.__main__", ["screenshot=1"], "screenshot must be true or false, got '1'"),
])
def test_every_command_reads_its_arguments_through_the_one_parser(module, argv, said, capsys):
    import importlib

    with pytest.raises(SystemExit) as stopped:
        importlib.import_module(module).main(argv)
    error = capsys.readouterr().err
    assert stopped.value.code == 2 and said in error and error.count("\n") == 1, error
