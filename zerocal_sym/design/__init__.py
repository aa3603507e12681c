"""Measurement-pose design (issue 5): the K measurement poses chosen by constrained
optimisation for a criterion, with the workspace's boundary scheme at the same K as
the baseline (the paper's scheme on a rectangle, the ring scheme on a cylinder).

Generic over the mechanism (issue 10): poses (K, n), joints (K, m), the p = m + n
parameters of the paper's Eq. (28); the design region is the workspace's shape.

Modules, each importing only from those before it: ``terms`` (per-pose terms
of the design model), ``constraints``, ``criteria``, ``order`` (visiting
order), ``exchange`` (discrete exchange), ``nlp`` (continuous design, Ipopt),
``optimize`` (driver, :func:`optimize_design`), ``verify`` (Monte Carlo) and
``plot``.  The public API is re-exported here.
"""
from zerocal_sym.design.terms import design_params, pose_terms
from zerocal_sym.design.constraints import (MAX_K, MIN_K, SCALE_RANGE_MM, TRAVEL_MODES, Constraints, CylinderRegion,
                                            DesignError, Region, check_design, make_constraints, make_region, min_k,
                                            workspace_region)
from zerocal_sym.design.criteria import CRITERIA, criteria_table, criterion_values, evaluate
from zerocal_sym.design.order import best_order
from zerocal_sym.design.exchange import candidate_grid, exchange_design
from zerocal_sym.design.nlp import PSD_FORM, continuous_design
from zerocal_sym.design.optimize import DesignResult, boundary_baseline, optimize_design, paper_baseline
from zerocal_sym.design.verify import default_true_errors, verify_design
from zerocal_sym.design.plot import plot_design

__all__ = [
    "CRITERIA", "MAX_K", "MIN_K", "PSD_FORM", "SCALE_RANGE_MM", "TRAVEL_MODES",
    "Constraints", "CylinderRegion", "DesignError", "DesignResult", "Region",
    "best_order", "boundary_baseline", "candidate_grid", "check_design", "continuous_design", "criteria_table",
    "criterion_values", "default_true_errors", "design_params", "evaluate", "exchange_design",
    "make_constraints", "make_region", "min_k", "optimize_design", "paper_baseline", "plot_design",
    "pose_terms", "verify_design", "workspace_region",
]
