"""replication.environment.variables: set for the block, put back as they were after it, an error too."""

import os

import pytest

from replication.environment import variables


def test_each_variable_is_set_in_the_block_and_as_before_after_it_even_after_an_error(monkeypatch):
    monkeypatch.setenv("REPLICATION_TEST_SET", "before")
    monkeypatch.delenv("REPLICATION_TEST_UNSET", raising=False)
    with pytest.raises(RuntimeError), variables({"REPLICATION_TEST_SET": "in", "REPLICATION_TEST_UNSET": "in"}):
        assert os.environ["REPLICATION_TEST_SET"] == os.environ["REPLICATION_TEST_UNSET"] == "in"
        raise RuntimeError("the block failed")
    assert os.environ["REPLICATION_TEST_SET"] == "before"
    assert "REPLICATION_TEST_UNSET" not in os.environ
