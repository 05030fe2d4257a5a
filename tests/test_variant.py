"""A request that changes a shipped experiment (its data, methods or settings) is the user's, decided from the
resolved config: it gets a report of its own and never the paper's name."""

import pytest

from replication.errors import ConfigError
from replication.paths import experiment_names
from replication.runner.variant import differences, report_name


@pytest.mark.parametrize("scale", ["quick", "paper"])
def test_every_shipped_experiment_as_shipped_is_the_papers(make_cfg, scale):
    for name in experiment_names():
        if "readings" in name:  # a multiverse writes its own report
            continue
        cfg = make_cfg(name, f"scale={scale}", "n_jobs=1", "base_seed=20261121")
        assert differences(cfg) == [], name
        assert report_name(cfg, []) == name


@pytest.mark.parametrize("overrides, said", [
    (("experiment.scenes.exp6_pets09.name=TUD-Campus",), 'scenes.exp6_pets09.name: "PETS09-S2L1" -> "TUD-Campus"'),
    (("experiment.methods.BIS-PF.beta=2.0",), "methods.BIS-PF.beta: 4.0 -> 2.0"),
    (("data.mot=../shared/data/mot/",), 'scenes.exp6_pets09.root: "../shared/data/mot" -> "../shared/data/mot/"'),
    (("+experiment.methods.Mine={label: mine, filter: bootstrap, n_particles: 10}",), "methods.Mine: added"),
])
def test_data_methods_and_settings_make_it_the_users(make_cfg, overrides, said):
    cfg = make_cfg("bis_pf_pets", "scale=quick", *overrides)
    found = differences(cfg)
    assert any(line.startswith(said) for line in found), found
    name = report_name(cfg, found)
    assert name.startswith("bis_pf_pets@") and len(name) == len("bis_pf_pets@") + 8  # a digest of the change
    assert report_name(make_cfg("bis_pf_pets", "scale=quick", "label=campus", *overrides), found) == "bis_pf_pets@campus"


def test_more_runs_are_the_same_experiment_and_a_bad_label_is_refused(make_cfg):
    assert differences(make_cfg("bis_pf_pets", "scale=quick", "experiment.runs.quick=3")) == []
    cfg = make_cfg("bis_pf_pets", "scale=quick", "label=../x")
    with pytest.raises(ConfigError, match="label"):
        report_name(cfg, ["a change"])


def test_sequences_read_from_a_folder_named_in_the_environment_are_the_users(make_cfg, monkeypatch):
    from replication.runner import variant
    from replication.scenes.factory import OTB

    monkeypatch.setattr(OTB, "root", "/data/my_otb")  # as $REPLICATION_OTB sets it at import
    found = variant.differences(make_cfg("hspf", "scale=quick"))
    assert found[0] == "data.otb: ../shared/data/otb -> /data/my_otb (from the environment)"
