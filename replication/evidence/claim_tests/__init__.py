"""Claim tests, one module per family; importing the package registers every test (:data:`CLAIM_TESTS`)."""

from replication.evidence.claim_tests import cells, order, ranked, threshold, uniformity  # noqa: F401  (each registers)
from replication.evidence.claim_tests.base import CLAIM_TESTS, READING_KEYS, ClaimSpec, ClaimTest, claim_spec, named

__all__ = ["CLAIM_TESTS", "READING_KEYS", "ClaimSpec", "ClaimTest", "claim_spec", "named"]
