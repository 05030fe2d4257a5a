"""A user's own filter for the replication harness: the auxiliary particle filter of Pitt and Shephard
(1999), named in an experiment as ``filter: auxiliary_pf.apf:auxiliary_pf`` or, once this distribution
is installed, ``filter: auxiliary_pf``."""

from auxiliary_pf.apf import AuxiliaryParticleFilter, auxiliary_pf

__all__ = ["AuxiliaryParticleFilter", "auxiliary_pf"]
