"""Every kind a config names comes in by one registry type (replication/kinds.py): a table, a decorator, a
base class's ``__init_subclass__`` or entry points read at the first lookup; an unknown name is one line
naming the known ones.  The scene kinds are one table whose attributes answer what the package asks of a
scene (real or drawn, its benchmark, its folder, whether people come and go)."""

import pytest

from replication.errors import ConfigError
from replication.kinds import Registry
from replication.scenes.factory import MOT, OTB, SCENE_KINDS, SYNTHETIC, scene_kind


def test_a_table_a_decorator_and_a_subclass_register_alike_and_keep_their_order():
    kinds: Registry = Registry("figure kind", {"line": len})

    @kinds.register("bars")
    def bars():
        return "drawn"

    class Base:
        def __init_subclass__(cls, name: str, **kwargs):
            super().__init_subclass__(**kwargs)
            kinds.register(name, cls)

    class Table(Base, name="table"):
        pass

    assert list(kinds) == ["line", "bars", "table"] and len(kinds) == 3
    assert kinds["bars"] is bars and bars() == "drawn" and kinds["table"] is Table
    assert kinds.items() == [("line", len), ("bars", bars), ("table", Table)]
    assert "bars" in kinds and "pie" not in kinds and ["unhashable"] not in kinds


@pytest.mark.parametrize("name", ["pie", None, ["a", "list"], {"a": "mapping"}])
def test_an_unknown_name_is_one_line_naming_the_known_ones(name):
    kinds = Registry("figure kind", {"line": len, "bars": len}, hint=" (or a path of your own)")
    with pytest.raises(ConfigError) as error:
        kinds[name]
    assert str(error.value) == (f"unknown figure kind {name!r}; known figure kinds: bars, line "
                                "(or a path of your own)")


def test_two_kinds_under_one_name_are_refused_one_kind_twice_is_not():
    kinds = Registry("task", {"scalar": len})
    kinds.register("scalar", len)
    with pytest.raises(ValueError, match="two tasks are registered as 'scalar'"):
        kinds.register("scalar", max)


def test_a_loader_is_read_at_the_first_lookup_and_again_after_forget():
    reads = []

    def load():
        reads.append(len(reads))
        return [("a", 1), ("b", 2)] if len(reads) == 1 else [("a", 1), ("b", 2), ("c", 3)]

    kinds = Registry("filter", load=load)
    assert reads == []  # nothing read at import
    assert kinds["b"] == 2 and list(kinds) == ["a", "b"] and len(reads) == 1
    kinds.forget()
    assert kinds["c"] == 3 and len(reads) == 2


def test_a_loader_that_fails_is_asked_again():
    answers = iter([ConfigError("not installed"), [("a", 1)]])

    def load():
        answer = next(answers)
        if isinstance(answer, Exception):
            raise answer
        return answer

    kinds = Registry("filter", load=load)
    with pytest.raises(ConfigError, match="not installed"):
        kinds["a"]
    assert kinds["a"] == 1


def test_the_scene_kinds_are_one_table_of_three():
    assert SCENE_KINDS.items() == [("synthetic", SYNTHETIC), ("otb", OTB), ("mot", MOT)]
    assert scene_kind({}) is SYNTHETIC and scene_kind({"kind": "otb", "name": "Girl"}) is OTB
    assert [kind.name for kind in SCENE_KINDS.values() if kind.real] == ["otb", "mot"]
    assert [kind.name for kind in SCENE_KINDS.values() if kind.open_set] == ["mot"]
    for kind in (OTB, MOT):  # a real kind says where its sequences are and finds them there
        assert kind.benchmark and kind.root and kind.shipped_root and kind.names and kind.find
    assert (OTB.counts_from, MOT.counts_from) == (0, 1)  # OTB's first: is 0-based, MOTChallenge's 1-based
    with pytest.raises(ConfigError, match=r"^unknown scene kind 'vot'; known scene kinds: mot, otb, synthetic$"):
        scene_kind({"kind": "vot"})


def test_an_unknown_scene_kind_is_one_line_naming_the_scene_before_any_run(make_cfg):
    from replication.runner.validate import prepare

    with pytest.raises(ConfigError) as error:
        prepare(make_cfg("demo_scene", "scale=quick", "experiment.scenes.synthetic_head.kind=vot"))
    assert str(error.value) == ("experiment.scenes.synthetic_head.kind: unknown scene kind 'vot'; known scene "
                                "kinds: mot, otb, synthetic")


def test_a_real_scene_without_its_sequence_is_refused_whatever_its_benchmark(make_cfg):
    from replication.runner.validate import check_scenes

    cfg = make_cfg("bis_pf_pets", "scale=quick", "~experiment.scenes.exp6_pets09.name")
    with pytest.raises(ConfigError, match=r"^experiment.scenes.exp6_pets09.name: a scene of kind mot names its "
                                          r"MOTChallenge sequence$"):
        check_scenes(cfg)


@pytest.mark.parametrize("experiment, scene, kind, said", [
    ("demo_scene", "synthetic_head", "mot", "a tracking experiment follows a fixed set of targets; a scene whose "
                                            "people come and go is the mot task's"),
    ("bis_pf_pets", "exp6_pets09", "otb", "a mot experiment needs model.scene naming a scene whose people come "
                                          "and go (kind: mot)"),
])
def test_a_task_refuses_a_scene_of_the_other_kind_of_targets(make_cfg, experiment, scene, kind, said):
    """Whether people come and go is the scene kind's (``open_set``), not its name compared."""
    from replication.runner.config import expand

    with pytest.raises(ConfigError) as error:
        expand(make_cfg(experiment, "scale=quick", f"experiment.scenes.{scene}.kind={kind}"))
    assert str(error.value).endswith(said) and "\n" not in str(error.value)
