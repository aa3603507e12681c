"""Generated CasADi builders for the mechanism ``planar_2dof``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/mechanism.py, derivations/planar_2dof.py
inputs hash: d7b3cdff5887eb71
sympy: 1.14.0
"""
import casadi as ca

NAME = 'planar_2dof'
POSE_NAMES = ['x', 'y']
JOINT_NAMES = ['theta1', 'theta2']
GEOMETRY_NAMES = ['e1x', 'e1y', 'e2x', 'e2y', 'L1', 'L2', 'l1', 'l2', 'cx', 'cy', 'dx', 'dy']
SOURCE_ERROR_NAMES = ['theta1', 'theta2', 'e1x', 'e1y', 'e2x', 'e2y', 'L1', 'L2', 'l1', 'l2', 'rMx', 'rMy']
FUNCTION_SIGNATURES = {
    'ik': ([('P', 2), ('g', 12)], [('theta', (2, 1)), ('ratio', (2, 1))]),
    'fk': ([('theta', 2), ('g', 12)], [('P', (2, 1))]),
    'pose_error_jacobian': ([('P', 2), ('theta', 2), ('g', 12)], [('J_src', (2, 10))]),
    'error_jacobian_full': ([('P', 2), ('theta', 2), ('g', 12)], [('J_full', (2, 10))]),
    'error_jacobian': ([('P', 2), ('theta', 2), ('g', 12)], [('J', (2, 2))]),
    'measuring': ([('P', 2), ('g', 12)], [('lam', (1, 1)), ('lam_hat', (2, 1))]),
    'g_row': ([('P', 2), ('theta', 2), ('g', 12)], [('row', (1, 4))]),
    'distance': ([('theta_cmd', 2), ('g', 12), ('err', 12)], [('rho', (1, 1))]),
    'transmission': ([('P', 2), ('theta', 2), ('g', 12)], [('s', (3, 1))]),
}


def _ik(P, g):
    """Inverse kinematics (branch continuous with home) and |K_i/r_i| <= 1 reach ratios."""
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
    t1 = e1y + t0
    t2 = -x
    t3 = e1x + t2
    t4 = t1**2 + t3**2
    t5 = (1/2)*(L1**2 - l1**2 + t4)/(L1*ca.sqrt(t4))
    t6 = e2y + t0
    t7 = e2x + t2
    t8 = t6**2 + t7**2
    t9 = (1/2)*(L2**2 - l2**2 + t8)/(L2*ca.sqrt(t8))
    theta = ca.vertcat(-ca.acos(t5) + ca.atan2(-t1, -t3), ca.acos(t9) + ca.atan2(-t6, -t7))
    ratio = ca.vertcat(t5, t9)
    return (theta, ratio,)


def _fk(theta, g):
    """Forward kinematics: circle intersection with the larger y."""
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
    t1 = -L2*ca.cos(theta2) - e2x + t0
    t2 = L1*ca.sin(theta1) + e1y
    t3 = -L2*ca.sin(theta2) - e2y + t2
    t4 = t1**2 + t3**2
    t5 = 1/t4
    t6 = l1**2
    t7 = -l2**2 + t4 + t6
    t8 = (1/2)*t5*t7
    t9 = ca.sqrt(-1/4*t5*t7**2 + t6)*ca.sign(t1)/ca.sqrt(t4)
    P = ca.vertcat(t0 - t1*t8 - t3*t9, t1*t9 + t2 - t3*t8)
    return (P,)


def _pose_error_jacobian(P, theta, g):
    """dP/d(source errors theta1 theta2 e1x e1y e2x e2y L1 L2 l1 l2), rad and mm."""
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
    t0 = ca.sin(theta1)
    t1 = ca.cos(theta1)
    t2 = e1x*t0 - e1y*t1 - t0*x + t1*y
    t3 = -y
    t4 = L1*t0 + e1y + t3
    t5 = -x
    t6 = ca.cos(theta2)
    t7 = L2*t6 + e2x + t5
    t8 = L1*t1 + e1x + t5
    t9 = ca.sin(theta2)
    t10 = L2*t9 + e2y + t3
    t11 = 1/t8
    t12 = t11*t4
    t13 = t12*t7
    t14 = t13/(t10 - t4*t7/t8)
    t15 = L1*t11
    t16 = 1/(t10 - t13)
    t17 = L2*t16*(e2x*t9 - e2y*t6 + t6*y - t9*x)
    t18 = t16*t7
    t19 = t11*t18
    t20 = t12*t18
    t21 = -t20
    t22 = t10*t16
    t23 = L1*t0**2 + L1*t1**2 + e1x*t1 + e1y*t0 - t0*y - t1*x
    t24 = t16*(L2*t6**2 + L2*t9**2 + e2x*t6 + e2y*t9 - t6*x - t9*y)
    t25 = l1*t11
    t26 = l2*t16
    J_src = ca.vertcat(
        ca.horzcat(-t15*(t14*t2 + t2), t12*t17, t11*(t18*t4 + t8), t11*(t19*t4**2 + t4), t21, -t12*t22, t11*(t20*t23 + t23), -t12*t24, -t25*(t14 + 1), t12*t26),
        ca.horzcat(t15*t18*t2, -t17, -t18, t21, t18, t22, -t19*t23, t24, t18*t25, -t26),
    )
    return (J_src,)


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
    t0 = -x
    t1 = ca.cos(theta1)
    t2 = L1*t1 + e1x + t0
    t3 = 1/t2
    t4 = ca.sin(theta1)
    t5 = e1x*t4 - e1y*t1 + t1*y - t4*x
    t6 = -y
    t7 = L1*t4 + e1y + t6
    t8 = ca.cos(theta2)
    t9 = L2*t8 + e2x + t0
    t10 = ca.sin(theta2)
    t11 = L2*t10 + e2y + t6
    t12 = t3*t7
    t13 = t12*t9
    t14 = t13/(t11 - t7*t9/t2)
    t15 = 1/(t11 - t13)
    t16 = t15*t9
    t17 = t16*t3
    t18 = L1*t1**2 + L1*t4**2 + e1x*t1 + e1y*t4 - t1*x - t4*y
    t19 = t12*t16
    t20 = l1*t3
    t21 = t15*(e2x*t10 - e2y*t8 - t10*x + t8*y)
    t22 = -t19
    t23 = t11*t15
    t24 = t15*(L2*t10**2 + L2*t8**2 + e2x*t8 + e2y*t10 - t10*y - t8*x)
    t25 = l2*t15
    J_full = ca.vertcat(
        ca.horzcat(-t3*(t14*t5 + t5), t3*(t16*t7 + t2), t3*(t17*t7**2 + t7), t3*(t18*t19 + t18), -t20*(t14 + 1), t12*t21, t22, -t12*t23, -t12*t24, t12*t25),
        ca.horzcat(t17*t5, -t16, t22, -t17*t18, t16*t20, -t21, t16, t23, t24, -t25),
    )
    return (J_full,)


def _error_jacobian(P, theta, g):
    """Paper Eq. (13): dP = J dq, dq = (L1 dth1, L2 dth2)."""
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
    t0 = -x
    t1 = ca.cos(theta1)
    t2 = L1*t1 + e1x + t0
    t3 = 1/t2
    t4 = ca.sin(theta1)
    t5 = e1x*t4 - e1y*t1 + t1*y - t4*x
    t6 = -y
    t7 = L1*t4 + e1y + t6
    t8 = ca.cos(theta2)
    t9 = L2*t8 + e2x + t0
    t10 = ca.sin(theta2)
    t11 = L2*t10 + e2y + t6
    t12 = t3*t7
    t13 = t12*t9
    t14 = 1/(t11 - t13)
    t15 = t14*(e2x*t10 - e2y*t8 - t10*x + t8*y)
    J = ca.vertcat(
        ca.horzcat(-t3*(t13*t5/(t11 - t7*t9/t2) + t5), t12*t15),
        ca.horzcat(t14*t3*t5*t9, -t15),
    )
    return (J,)


def _measuring(P, g):
    """Nominal measuring-mechanism length |P - c - d| and its unit vector."""
    x = P[0]
    y = P[1]
    cx = g[8]
    cy = g[9]
    dx = g[10]
    dy = g[11]
    t0 = cx + dx - x
    t1 = cy + dy - y
    t2 = ca.sqrt(t0**2 + t1**2)
    t3 = 1/t2
    lam = ca.vertcat(t2)
    lam_hat = ca.vertcat(-t0*t3, -t1*t3)
    return (lam, lam_hat,)


def _g_row(P, theta, g):
    """Identification row g_k = lam_hat^T [J, -I] (paper Eq. 28)."""
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
    t0 = -x
    t1 = ca.cos(theta1)
    t2 = L1*t1 + e1x + t0
    t3 = 1/t2
    t4 = cx + dx + t0
    t5 = -y
    t6 = cy + dy + t5
    t7 = 1/ca.sqrt(t4**2 + t6**2)
    t8 = ca.sin(theta2)
    t9 = ca.sin(theta1)
    t10 = L1*t9 + e1y + t5
    t11 = ca.cos(theta2)
    t12 = L2*t11 + e2x + t0
    t13 = 1/(L2*t8 + e2y - t10*t12/t2 + t5)
    t14 = e1x*t9 - e1y*t1 + t1*y - t9*x
    t15 = t12*t13*t14
    t16 = t10*t3
    row = ca.vertcat(
        ca.horzcat(-t3*t7*(t15*t6 + t4*(-t14 - t15*t16)), t13*t7*(-t16*t4 + t6)*(e2x*t8 - e2y*t11 + t11*y - t8*x), t4*t7, t6*t7),
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
    t0 = L1 + d_L1
    t1 = d_theta1 + theta1
    t2 = t0*ca.cos(t1)
    t3 = L2 + d_L2
    t4 = d_theta2 + theta2
    t5 = d_e1x - d_e2x + e1x - e2x + t2 - t3*ca.cos(t4)
    t6 = t0*ca.sin(t1)
    t7 = d_e1y - d_e2y + e1y - e2y - t3*ca.sin(t4) + t6
    t8 = t5**2 + t7**2
    t9 = 1/t8
    t10 = (d_l1 + l1)**2
    t11 = t10 + t8 - (d_l2 + l2)**2
    t12 = t11*t9
    t13 = 2*ca.sqrt(t10 - 1/4*t11**2*t9)*ca.sign(t5)/ca.sqrt(t8)
    rho = ca.vertcat((1/2)*ca.sqrt((2*cx - 2*d_e1x + 2*d_rMx + 2*dx - 2*e1x + t12*t5 + t13*t7 - 2*t2)**2 + (2*cy - 2*d_e1y + 2*d_rMy + 2*dy - 2*e1y + t12*t7 - t13*t5 - 2*t6)**2))
    return (rho,)


def _transmission(P, theta, g):
    """sin of the transmission angles (u_i, w_i) and of the angle (w_1, w_2)."""
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
    t0 = 1/l1
    t1 = ca.cos(theta1)
    t2 = -y
    t3 = ca.sin(theta1)
    t4 = L1*t3 + e1y + t2
    t5 = -x
    t6 = L1*t1 + e1x + t5
    t7 = 1/l2
    t8 = ca.cos(theta2)
    t9 = ca.sin(theta2)
    t10 = L2*t9 + e2y + t2
    t11 = L2*t8 + e2x + t5
    s = ca.vertcat(t0*(-t1*t4 + t3*t6), t7*(-t10*t8 + t11*t9), t0*t7*(t10*t6 - t11*t4))
    return (s,)


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
