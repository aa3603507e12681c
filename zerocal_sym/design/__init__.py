"""Measurement-pose design: the K measurement poses chosen by constrained
optimisation for a criterion, with the workspace's boundary scheme at the same K as
the baseline (the paper's scheme on a rectangle, the ring scheme on a cylinder, the
corner scheme on a box).

Generic over the mechanism: poses (K, n), joints (K, m), the p parameters of the
mechanism's identified set (the paper's Eq. (28) for its robot); the design region is
the workspace's shape; joint quantities in the joints' unit (deg for revolute joints,
mm for prismatic ones: :func:`zerocal_sym.design.terms.okey`).

Modules, each importing only from those before it: ``terms`` (per-pose terms
of the design model), ``limits`` (bounds on K, defaults, :class:`DesignError`),
``regions`` (the reachable set, clipped; imported lazily by
``shapes`` and ``constraints``), ``shapes`` (regions of the workspace's shape, any region
validated), ``constraints`` (and the feasibility checks), ``criteria``, ``order``
(visiting order), ``exchange`` (discrete exchange), ``nlp`` (continuous
design, Ipopt), the approximate designs -- ``posemodel`` (the
order-free pose model, criteria), ``measure`` (the optimal measure and its
certificate), ``rounding`` (K poses from a measure), ``fewest`` (fewest
poses for a target CRLB; imports ``approx`` lazily), ``approx`` (the
approximate design: candidates, travel windows, refinement, the bound),
``mse`` (the bias-aware measure) --, ``optimize`` (driver,
:func:`optimize_design`), ``verify`` (Monte Carlo) and ``plot``.  The public
API is re-exported here.
"""
from zerocal_sym.design.terms import design_params, pose_terms
from zerocal_sym.design.limits import MAX_K, MAX_K_EXACT, MIN_K, SCALE_RANGE_MM, TRAVEL_MODES, DesignError, min_k
from zerocal_sym.design.shapes import CylinderRegion, Region, make_region, workspace_region
from zerocal_sym.design.constraints import Constraints, check_design, make_constraints
from zerocal_sym.design.criteria import CRITERIA, criteria_table, criterion_values, evaluate, position_report
from zerocal_sym.design.order import best_order
from zerocal_sym.design.exchange import candidate_grid, exchange_design
from zerocal_sym.design.nlp import PSD_FORM, continuous_design
from zerocal_sym.design.regions import Box, Polygon, ReachableRegion, make_reachable
from zerocal_sym.design.approx import APPROX_CRITERIA, ApproxDesign, approximate_design
from zerocal_sym.design.rounding import efficient_rounding, realize
from zerocal_sym.design.fewest import fewest_poses
from zerocal_sym.design.optimize import (EXACT_MAX_K, DesignResult, boundary_baseline, choose_baseline,
                                         optimize_design, paper_baseline)
from zerocal_sym.design.verify import default_true_errors, verify_design
from zerocal_sym.design.plot import plot_design

__all__ = [
    "APPROX_CRITERIA", "CRITERIA", "EXACT_MAX_K", "MAX_K", "MAX_K_EXACT", "MIN_K", "PSD_FORM", "SCALE_RANGE_MM",
    "TRAVEL_MODES",
    "ApproxDesign", "Box", "Constraints", "CylinderRegion", "DesignError", "DesignResult", "Polygon",
    "ReachableRegion", "Region",
    "approximate_design", "best_order", "boundary_baseline", "candidate_grid", "check_design", "choose_baseline",
    "continuous_design", "criteria_table", "criterion_values", "default_true_errors", "design_params",
    "efficient_rounding", "evaluate", "exchange_design", "fewest_poses", "make_constraints", "make_reachable",
    "make_region", "min_k", "optimize_design", "paper_baseline", "plot_design", "pose_terms", "position_report",
    "realize", "verify_design", "workspace_region",
]
