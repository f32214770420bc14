"""Hopper theory for plane-flow (wedge) hoppers: critical outlet widths (McLean, Jenike, Enstad),
wall stresses (Walker/Walters, Janssen), discharge rates (Beverloo, Rose–Tanaka), the kinematic
velocity model and the mass/funnel-flow boundary. See README.md in this directory.

Stable high-level API::

    from bulkflow.theory import Material, Hopper, critical_width_estimates

One module per theory: :mod:`.mohr`, :mod:`.flow_function`, :mod:`.beverloo`, :mod:`.mclean`,
:mod:`.jenike`, :mod:`.enstad`, :mod:`.walker`, :mod:`.janssen`, :mod:`.kinematic`,
:mod:`.flow_mode`; the thesis cases in :mod:`.cases`; the CLI in :mod:`.cli`.
"""
from .model import (CONSOLIDATION_ROUTES, DEFAULT_READINGS, Hopper, Material,
                    critical_width_estimates, enstad_outlet_arch)
from .enstad import arch_centre
from .mohr import c_from_fc, delta_mod_deg, fc_from_c
from .flow_function import BilinearFlowFunction, LinearFlowFunction

__all__ = ["Material", "Hopper", "critical_width_estimates", "enstad_outlet_arch", "arch_centre",
           "CONSOLIDATION_ROUTES",
           "DEFAULT_READINGS", "fc_from_c", "c_from_fc", "delta_mod_deg",
           "LinearFlowFunction", "BilinearFlowFunction"]
