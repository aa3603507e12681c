"""Generated CasADi builders for the mechanism ``planar_2dof``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/geometry.py, derivations/mechanism.py, derivations/mechanisms/planar_2dof.py
inputs hash: 5f5101e89615e807
sympy: 1.14.0
"""
import casadi as ca

NAME = 'planar_2dof'
#: where this module was derived from: a module name, or a .py file relative to this module
DERIVATION = 'derivations.mechanisms.planar_2dof'
DESCRIPTION = '2-DOF translational parallel robot of Mei et al. 2017 (two RR limbs, planar)'
POSE_NAMES = ['x', 'y']
JOINT_NAMES = ['theta1', 'theta2']
GEOMETRY_NAMES = ['e1x', 'e1y', 'e2x', 'e2y', 'L1', 'L2', 'l1', 'l2', 'cx', 'cy', 'dx', 'dy']
GEOMETRY_UNITS = {'e1x': 'mm', 'e1y': 'mm', 'e2x': 'mm', 'e2y': 'mm', 'L1': 'mm', 'L2': 'mm', 'l1': 'mm', 'l2': 'mm', 'cx': 'mm', 'cy': 'mm', 'dx': 'mm', 'dy': 'mm'}
JOINT_KINDS = ['revolute', 'revolute']
POSE_UNITS = {'x': 'mm', 'y': 'mm'}
#: (name, role, unit, target, lever arm) of each source error, in vector order
SOURCE_ERRORS = [
    ('theta1', 'zero_offset', 'rad', 'theta1', 'L1'),
    ('theta2', 'zero_offset', 'rad', 'theta2', 'L2'),
    ('e1x', 'geometry', 'mm', 'e1x', None),
    ('e1y', 'geometry', 'mm', 'e1y', None),
    ('e2x', 'geometry', 'mm', 'e2x', None),
    ('e2y', 'geometry', 'mm', 'e2y', None),
    ('L1', 'geometry', 'mm', 'L1', None),
    ('L2', 'geometry', 'mm', 'L2', None),
    ('l1', 'geometry', 'mm', 'l1', None),
    ('l2', 'geometry', 'mm', 'l2', None),
    ('rMx', 'measuring', 'mm', 'cx', None),
    ('rMy', 'measuring', 'mm', 'cy', None),
]
SOURCE_ERROR_NAMES = ['theta1', 'theta2', 'e1x', 'e1y', 'e2x', 'e2y', 'L1', 'L2', 'l1', 'l2', 'rMx', 'rMy']
HOME_JOINTS = [0.0, 3.141592653589793]
#: None (HOME_JOINTS), 'workspace centre' or the name of the function giving the home pose
HOME_POSE = None
MEASURING_BASE = ['cx', 'cy']
MEASURING_OFFSET = ['dx', 'dy']
GAUGE_NAMES = ['translation x', 'translation y', 'rotation about O']
GAUGE_FIX = ['e1x', 'e1y', 'e2y']
WORKSPACE = 'rectangle'
WORKSPACE_DEFAULTS = {}
ALIASES = {'ex': {'e1x': 1.0, 'e2x': -1.0}, 'ey': {'e1y': 1.0, 'e2y': 1.0}, 'L': {'L1': 1.0, 'L2': 1.0}, 'l': {'l1': 1.0, 'l2': 1.0}}
LIST_ALIASES = {}
DEFAULTS = {}
PARAM_SETS = {'lengths': ('L1', 'L2', 'l1', 'l2'), 'base': ('e1x', 'e1y', 'e2x', 'e2y')}
DEFAULT_SET = ('theta1', 'theta2', 'rMx', 'rMy')
NOISE = {}
POSITIVE = ['L1', 'L2', 'l1', 'l2']
FUNCTION_SIGNATURES = {
    'ik': ([('P', 2), ('g', 12)], [('theta', (2, 1)), ('ratio', (2, 1))]),
    'fk': ([('theta', 2), ('g', 12)], [('P', (2, 1))]),
    'transmission': ([('P', 2), ('theta', 2), ('g', 12)], [('s', (3, 1))]),
    'pose_error_jacobian': ([('P', 2), ('theta', 2), ('g', 12)], [('J_src', (2, 10))]),
    'error_jacobian': ([('P', 2), ('theta', 2), ('g', 12)], [('J', (2, 2))]),
    'measuring': ([('P', 2), ('g', 12)], [('lam', (1, 1)), ('lam_hat', (2, 1))]),
    'g_row': ([('P', 2), ('theta', 2), ('g', 12)], [('row', (1, 4))]),
    'distance': ([('theta_cmd', 2), ('g', 12), ('err', 12)], [('rho', (1, 1))]),
    'gauge': ([('g', 12)], [('Z', (12, 3))]),
    'error_jacobian_full': ([('P', 2), ('theta', 2), ('g', 12)], [('J_full', (2, 10))]),
    'sketch': ([('P', 2), ('theta', 2), ('g', 12)], [('segments', (2, 10))]),
}


def _ik(P, g):
    """Inverse kinematics on the chosen branch and the reach ratios (|ratio| <= 1 where reachable)."""
    x = P[0]
    y = P[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    t0 = -y
    t1 = -e1y - t0
    t2 = -x
    t3 = -e1x - t2
    t4 = t1**2 + t3**2
    t5 = (1/2)*(L1**2 - l1**2 + t4)/(L1*ca.sqrt(t4))
    t6 = -e2y - t0
    t7 = -e2x - t2
    t8 = t6**2 + t7**2
    t9 = (1/2)*(L2**2 - l2**2 + t8)/(L2*ca.sqrt(t8))
    theta = ca.vertcat(-ca.acos(t5) + ca.atan2(t1, t3), ca.acos(t9) + ca.atan2(t6, t7))
    ratio = ca.vertcat(t5, t9)
    return (theta, ratio,)


def _fk(theta, g):
    """Forward kinematics on the chosen assembly mode."""
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    t0 = L1*ca.cos(theta1) + e1x
    t1 = L2*ca.cos(theta2) + e2x - t0
    t2 = L1*ca.sin(theta1) + e1y
    t3 = -L2*ca.sin(theta2) - e2y + t2
    t4 = -t3
    t5 = t1**2 + t4**2
    t6 = 1/t5
    t7 = l1**2
    t8 = -l2**2 + t5 + t7
    t9 = (1/2)*t6*t8
    t10 = ca.sqrt(-1/4*t6*t8**2 + t7)*ca.sign(t1)/ca.sqrt(t5)
    P = ca.vertcat(t0 + t1*t9 + t10*t3, t1*t10 + t2 + t4*t9)
    return (P,)


def _transmission(P, theta, g):
    """Singularity indicators: |s| >= margin away from a singular configuration."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    t0 = ca.cos(theta1)
    t1 = 1/l1
    t2 = -y
    t3 = ca.sin(theta1)
    t4 = t1*(-L1*t3 - e1y - t2)
    t5 = -x
    t6 = -L1*t0 - e1x - t5
    t7 = ca.cos(theta2)
    t8 = 1/l2
    t9 = ca.sin(theta2)
    t10 = -L2*t9 - e2y - t2
    t11 = t8*(-L2*t7 - e2x - t5)
    s = ca.vertcat(t0*t4 - t1*t3*t6, t10*t7*t8 - t11*t9, t1*t10*t6*t8 - t11*t4)
    return (s,)


def _pose_error_jacobian(P, theta, g):
    """dP/d(robot source errors theta1 theta2 e1x e1y e2x e2y L1 L2 l1 l2), per rad or mm (implicit differentiation)."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    t0 = 2*e1x
    t1 = ca.sin(theta1)
    t2 = L1*t1
    t3 = ca.cos(theta1)
    t4 = 2*y
    t5 = L1*t3
    t6 = 2*L1*e1y*t3 + 2*L1*t1*x - t0*t2 - t4*t5
    t7 = 4*e1y
    t8 = 4*x
    t9 = ca.sin(theta2)
    t10 = ca.cos(theta2)
    t11 = L2*t10
    t12 = L2*t9
    t13 = 1/(4*L1*L2*t3*t9 + 4*L1*e2y*t3 + 4*L1*t1*x + 4*L2*e1x*t9 + 4*L2*t10*y + 4*e1x*e2y - 4*e1x*y + 4*e1y*x - 4*e2x*t2 - e2x*t7 + 4*e2x*y - e2y*t8 - 4*t11*t2 - t11*t7 - t12*t8 - 4*t5*y)
    t14 = 2*e2y
    t15 = -t4
    t16 = 2*L2
    t17 = t14 + t15 + t16*t9
    t18 = -t13*t17
    t19 = 2*e2x
    t20 = 2*L2*e2y*t10 + 2*L2*t9*x - t11*t4 - t12*t19
    t21 = 2*e1y
    t22 = 2*L1
    t23 = t1*t22 + t15 + t21
    t24 = t13*t23
    t25 = 2*x
    t26 = -t25
    t27 = t0 + t22*t3 + t26
    t28 = t10*t16 + t19 + t26
    t29 = -t24*t28
    t30 = t0*t3 + t1**2*t22 + t1*t21 - t1*t4 + t22*t3**2 - t25*t3
    t31 = t10**2*t16 + t10*t19 - t10*t25 + t14*t9 + t16*t9**2 - t4*t9
    t32 = 2*l1
    t33 = 2*l2
    t34 = t13*t28
    t35 = -t27
    t36 = t13*t35
    J_src = ca.vertcat(
        ca.horzcat(-t18*t6, -t20*t24, -t18*t27, -t18*t23, t29, -t17*t24, -t18*t30, -t24*t31, t18*t32, t24*t33),
        ca.horzcat(-t34*t6, -t20*t36, -t27*t34, t29, -t34*t35, -t17*t36, -t30*t34, -t31*t36, t32*t34, t33*t36),
    )
    return (J_src,)


def _error_jacobian(P, theta, g):
    """dP/d(offsets as lengths: lever_i dtheta_i for a revolute joint, ds_i for a prismatic one) (paper Eq. 13 in n dimensions)."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    t0 = 2*y
    t1 = -t0
    t2 = ca.sin(theta2)
    t3 = 2*L2
    t4 = 4*e1y
    t5 = 4*x
    t6 = ca.sin(theta1)
    t7 = L1*t6
    t8 = ca.cos(theta1)
    t9 = L1*t8
    t10 = ca.cos(theta2)
    t11 = L2*t10
    t12 = L2*t2
    t13 = 1/(4*L1*L2*t2*t8 + 4*L1*e2y*t8 + 4*L1*t6*x + 4*L2*e1x*t2 + 4*L2*t10*y + 4*e1x*e2y - 4*e1x*y + 4*e1y*x - e2x*t4 - 4*e2x*t7 + 4*e2x*y - e2y*t5 - t11*t4 - 4*t11*t7 - t12*t5 - 4*t9*y)
    t14 = 2*e1x
    t15 = t13*(2*L1*e1y*t8 + 2*L1*t6*x - t0*t9 - t14*t7)/L1
    t16 = 2*L1
    t17 = 2*e2x
    t18 = t13*(2*L2*e2y*t10 + 2*L2*t2*x - t0*t11 - t12*t17)/L2
    t19 = -2*x
    J = ca.vertcat(
        ca.horzcat(-t15*(-2*e2y - t1 - t2*t3), -t18*(2*e1y + t1 + t16*t6)),
        ca.horzcat(-t15*(t10*t3 + t17 + t19), -t18*(-t14 - t16*t8 - t19)),
    )
    return (J,)


def _measuring(P, g):
    """Nominal measuring-mechanism length |O2 - O1| and its unit vector."""
    x = P[0]
    y = P[1]
    cx = g[8]
    cy = g[9]
    dx = g[10]
    dy = g[11]
    t0 = -cx - dx + x
    t1 = -cy - dy + y
    t2 = ca.sqrt(t0**2 + t1**2)
    t3 = 1/t2
    lam = ca.vertcat(t2)
    lam_hat = ca.vertcat(t0*t3, t1*t3)
    return (lam, lam_hat,)


def _g_row(P, theta, g):
    """Identification row g_k = d rho / d(offsets as lengths, measuring errors) (paper Eq. 28: lam_hat^T [J, -I] for lambda = P - c - d)."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    cx = g[8]
    cy = g[9]
    dx = g[10]
    dy = g[11]
    t0 = 2*y
    t1 = -t0
    t2 = ca.sin(theta2)
    t3 = 2*L2
    t4 = 4*e1y
    t5 = 4*x
    t6 = ca.sin(theta1)
    t7 = L1*t6
    t8 = ca.cos(theta1)
    t9 = L1*t8
    t10 = ca.cos(theta2)
    t11 = L2*t10
    t12 = L2*t2
    t13 = 1/(4*L1*L2*t2*t8 + 4*L1*e2y*t8 + 4*L1*t6*x + 4*L2*e1x*t2 + 4*L2*t10*y + 4*e1x*e2y - 4*e1x*y + 4*e1y*x - e2x*t4 - 4*e2x*t7 + 4*e2x*y - e2y*t5 - t11*t4 - 4*t11*t7 - t12*t5 - 4*t9*y)
    t14 = -cx - dx + x
    t15 = -cy - dy + y
    t16 = 1/ca.sqrt(t14**2 + t15**2)
    t17 = t14*t16
    t18 = t13*t17
    t19 = 2*e1x
    t20 = (2*L1*e1y*t8 + 2*L1*t6*x - t0*t9 - t19*t7)/L1
    t21 = 2*e2x
    t22 = -2*x
    t23 = t15*t16
    t24 = t13*t23
    t25 = 2*L1
    t26 = (2*L2*e2y*t10 + 2*L2*t2*x - t0*t11 - t12*t21)/L2
    row = ca.vertcat(
        ca.horzcat(-t18*t20*(-2*e2y - t1 - t2*t3) - t20*t24*(t10*t3 + t21 + t22), -t18*t26*(2*e1y + t1 + t25*t6) - t24*t26*(-t19 - t22 - t25*t8), -t17, -t23),
    )
    return (row,)


def _distance(theta_cmd, g, err):
    """Exact distance O1'O2' for commanded joints, nominal geometry and source errors."""
    theta1 = theta_cmd[0]
    theta2 = theta_cmd[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    cx = g[8]
    cy = g[9]
    dx = g[10]
    dy = g[11]
    d_theta1 = err[0]
    d_theta2 = err[1]
    d_e1x = err[2]
    d_e1y = err[3]
    d_e2x = err[4]
    d_e2y = err[5]
    d_L1 = err[6]
    d_L2 = err[7]
    d_l1 = err[8]
    d_l2 = err[9]
    d_rMx = err[10]
    d_rMy = err[11]
    t0 = L2 + d_L2
    t1 = d_theta2 + theta2
    t2 = L1 + d_L1
    t3 = d_theta1 + theta1
    t4 = d_e1x + e1x + t2*ca.cos(t3)
    t5 = d_e2x + e2x + t0*ca.cos(t1) - t4
    t6 = d_e1y + e1y + t2*ca.sin(t3)
    t7 = -d_e2y - e2y - t0*ca.sin(t1) + t6
    t8 = -t7
    t9 = t5**2 + t8**2
    t10 = 1/t9
    t11 = (d_l1 + l1)**2
    t12 = t11 + t9 - (d_l2 + l2)**2
    t13 = (1/2)*t10*t12
    t14 = ca.sqrt(-1/4*t10*t12**2 + t11)*ca.sign(t5)/ca.sqrt(t9)
    rho = ca.vertcat(ca.sqrt((-cx - d_rMx - dx + t13*t5 + t14*t7 + t4)**2 + (-cy - d_rMy - dy + t13*t8 + t14*t5 + t6)**2))
    return (rho,)


def _gauge(g):
    """Gauge motions (columns): source-error directions no distance change can see."""
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    cx = g[8]
    cy = g[9]
    dx = g[10]
    dy = g[11]
    Z = ca.vertcat(
        ca.horzcat(0, 0, 1),
        ca.horzcat(0, 0, 1),
        ca.horzcat(1, 0, -e1y),
        ca.horzcat(0, 1, e1x),
        ca.horzcat(1, 0, -e2y),
        ca.horzcat(0, 1, e2x),
        ca.horzcat(0, 0, 0),
        ca.horzcat(0, 0, 0),
        ca.horzcat(0, 0, 0),
        ca.horzcat(0, 0, 0),
        ca.horzcat(1, 0, -cy - dy),
        ca.horzcat(0, 1, cx + dx),
    )
    return (Z,)


def _error_jacobian_full(P, theta, g):
    """Paper Eq. (12): dP = J' dq', dq' = (L1 dth1, de1x, de1y, dL1, dl1, L2 dth2, ...)."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    l1 = g[6]
    l2 = g[7]
    t0 = 4*e1y
    t1 = 4*x
    t2 = ca.sin(theta1)
    t3 = L1*t2
    t4 = ca.cos(theta1)
    t5 = L1*t4
    t6 = ca.sin(theta2)
    t7 = ca.cos(theta2)
    t8 = L2*t7
    t9 = L2*t6
    t10 = 1/(4*L1*L2*t4*t6 + 4*L1*e2y*t4 + 4*L1*t2*x + 4*L2*e1x*t6 + 4*L2*t7*y + 4*e1x*e2y - 4*e1x*y + 4*e1y*x - e2x*t0 - 4*e2x*t3 + 4*e2x*y - e2y*t1 - t0*t8 - t1*t9 - 4*t3*t8 - 4*t5*y)
    t11 = 2*e2y
    t12 = 2*y
    t13 = -t12
    t14 = 2*L2
    t15 = t11 + t13 + t14*t6
    t16 = -t10*t15
    t17 = 2*e1x
    t18 = (2*L1*e1y*t4 + 2*L1*t2*x - t12*t5 - t17*t3)/L1
    t19 = 2*x
    t20 = -t19
    t21 = 2*L1
    t22 = t17 + t20 + t21*t4
    t23 = 2*e1y
    t24 = t13 + t2*t21 + t23
    t25 = -t12*t2 + t17*t4 - t19*t4 + t2**2*t21 + t2*t23 + t21*t4**2
    t26 = 2*l1
    t27 = t10*t24
    t28 = 2*e2x
    t29 = (2*L2*e2y*t7 + 2*L2*t6*x - t12*t8 - t28*t9)/L2
    t30 = t14*t7 + t20 + t28
    t31 = -t27*t30
    t32 = t11*t6 - t12*t6 + t14*t6**2 + t14*t7**2 - t19*t7 + t28*t7
    t33 = 2*l2
    t34 = t10*t30
    t35 = -t22
    t36 = t10*t35
    J_full = ca.vertcat(
        ca.horzcat(-t16*t18, -t16*t22, -t16*t24, -t16*t25, t16*t26, -t27*t29, t31, -t15*t27, -t27*t32, t27*t33),
        ca.horzcat(-t18*t34, -t22*t34, t31, -t25*t34, t26*t34, -t29*t36, -t34*t35, -t15*t36, -t32*t36, t33*t36),
    )
    return (J_full,)


def _sketch(P, theta, g):
    """The robot drawn as line segments (columns 2k and 2k+1: the ends of segment k), mm."""
    x = P[0]
    y = P[1]
    theta1 = theta[0]
    theta2 = theta[1]
    e1x = g[0]
    e1y = g[1]
    e2x = g[2]
    e2y = g[3]
    L1 = g[4]
    L2 = g[5]
    t0 = L1*ca.cos(theta1) + e1x
    t1 = L2*ca.cos(theta2) + e2x
    t2 = L1*ca.sin(theta1) + e1y
    t3 = L2*ca.sin(theta2) + e2y
    segments = ca.vertcat(
        ca.horzcat(e1x, e2x, e1x, t0, t0, x, e2x, t1, t1, x),
        ca.horzcat(e1y, e2y, e1y, t2, t2, y, e2y, t3, t3, y),
    )
    return (segments,)


def build_functions():
    """Build every CasADi ``Function`` of this mechanism (SX graphs).

    Returns
    -------
    dict of str -> casadi.Function
    """
    funcs = {}
    for fname, (ins, outs) in FUNCTION_SIGNATURES.items():
        syms = [ca.SX.sym(n, k) for n, k in ins]
        res = globals()['_' + fname](*syms)
        funcs[fname] = ca.Function(fname, syms, list(res), [n for n, _ in ins], [n for n, _ in outs])
    return funcs
