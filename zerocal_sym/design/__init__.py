"""Measurement-pose design (issue 5): the K measurement poses chosen by constrained
optimisation for a criterion, with the paper's scheme at the same K as the baseline.

Modules, each importing only from those before it: ``terms`` (per-pose terms
of the design model), ``constraints``, ``criteria``, ``order`` (visiting
order), ``exchange`` (discrete exchange), ``nlp`` (continuous design, Ipopt),
``optimize`` (driver, :func:`optimize_design`), ``verify`` (Monte Carlo) and
``plot``.  The public API is re-exported here.
"""
from zerocal_sym.design.terms import pose_terms
from zerocal_sym.design.constraints import (MAX_K, MIN_K, SCALE_RANGE_MM, TRAVEL_MODES, Constraints, DesignError,
                                            Region, check_design, make_constraints)
from zerocal_sym.design.criteria import CRITERIA, criterion_values, evaluate
from zerocal_sym.design.order import best_order
from zerocal_sym.design.exchange import candidate_grid, exchange_design
from zerocal_sym.design.nlp import PSD_FORM, continuous_design
from zerocal_sym.design.optimize import DesignResult, optimize_design, paper_baseline
from zerocal_sym.design.verify import verify_design
from zerocal_sym.design.plot import plot_design

__all__ = [
    "CRITERIA", "MAX_K", "MIN_K", "PSD_FORM", "SCALE_RANGE_MM", "TRAVEL_MODES",
    "Constraints", "DesignError", "DesignResult", "Region",
    "best_order", "candidate_grid", "check_design", "continuous_design", "criterion_values", "evaluate",
    "exchange_design", "make_constraints", "optimize_design", "paper_baseline", "plot_design", "pose_terms",
    "verify_design",
]
