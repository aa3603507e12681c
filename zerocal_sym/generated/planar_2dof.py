"""Generated CasADi builders for the mechanism ``planar_2dof``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/mechanism.py, derivations/planar_2dof.py
inputs hash: 0c9aacba7b1a46f8
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
    t1 = L1*t0
    t2 = ca.cos(theta1)
    t3 = t2*y
    t4 = ca.cos(theta2)
    t5 = L2*t4
    t6 = ca.sin(theta2)
    t7 = L2*t6
    t8 = L1*t2
    t9 = t0*x
    t10 = t4*y
    t11 = 1/(L1*t3 - L1*t9 - L2*t10 - e1x*e2y - e1x*t7 + e1x*y + e1y*e2x + e1y*t5 - e1y*x + e2x*t1 - e2x*y - e2y*t8 + e2y*x + t1*t5 - t7*t8 + t7*x)
    t12 = -y
    t13 = t11*(e2y + t12 + t7)
    t14 = L1*(e1x*t0 - e1y*t2 + t3 - t9)
    t15 = e1y + t1 + t12
    t16 = t11*t15
    t17 = L2*(e2x*t6 - e2y*t4 + t10 - t6*x)
    t18 = -x
    t19 = e1x + t18 + t8
    t20 = -t13*t19
    t21 = t13*t15
    t22 = e2x + t18 + t5
    t23 = t16*t22
    t24 = L1*t0**2 + L1*t2**2 + e1x*t2 + e1y*t0 - t0*y - t2*x
    t25 = L2*t4**2 + L2*t6**2 + e2x*t4 + e2y*t6 - t4*x - t6*y
    t26 = t11*t22
    t27 = t11*t19
    t28 = t19*t26
    J_src = ca.vertcat(
        ca.horzcat(t13*t14, -t16*t17, t20, -t21, t23, t21, -t13*t24, t16*t25, l1*t13, -l2*t16),
        ca.horzcat(-t14*t26, t17*t27, t28, t23, -t28, t20, t24*t26, -t25*t27, -l1*t26, l2*t27),
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
    t0 = ca.sin(theta1)
    t1 = ca.cos(theta1)
    t2 = t1*y
    t3 = t0*x
    t4 = e1x*t0 - e1y*t1 + t2 - t3
    t5 = L1*t0
    t6 = ca.cos(theta2)
    t7 = L2*t6
    t8 = ca.sin(theta2)
    t9 = L2*t8
    t10 = L1*t1
    t11 = t6*y
    t12 = 1/(L1*t2 - L1*t3 - L2*t11 - e1x*e2y - e1x*t9 + e1x*y + e1y*e2x + e1y*t7 - e1y*x + e2x*t5 - e2x*y - e2y*t10 + e2y*x - t10*t9 + t5*t7 + t9*x)
    t13 = -y
    t14 = t12*(e2y + t13 + t9)
    t15 = -x
    t16 = e1x + t10 + t15
    t17 = -t14*t16
    t18 = e1y + t13 + t5
    t19 = t14*t18
    t20 = L1*t0**2 + L1*t1**2 + e1x*t1 + e1y*t0 - t0*y - t1*x
    t21 = e2x*t8 - e2y*t6 + t11 - t8*x
    t22 = t12*t18
    t23 = e2x + t15 + t7
    t24 = t22*t23
    t25 = L2*t6**2 + L2*t8**2 + e2x*t6 + e2y*t8 - t6*x - t8*y
    t26 = t12*t23
    t27 = t16*t26
    t28 = t12*t16
    J_full = ca.vertcat(
        ca.horzcat(t14*t4, t17, -t19, -t14*t20, l1*t14, -t21*t22, t24, t19, t22*t25, -l2*t22),
        ca.horzcat(-t26*t4, t27, t24, t20*t26, -l1*t26, t21*t28, -t27, t17, -t25*t28, l2*t28),
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
    t0 = -y
    t1 = ca.sin(theta2)
    t2 = L2*t1
    t3 = ca.sin(theta1)
    t4 = L1*t3
    t5 = ca.cos(theta1)
    t6 = t5*y
    t7 = ca.cos(theta2)
    t8 = L2*t7
    t9 = L1*t5
    t10 = t3*x
    t11 = t7*y
    t12 = 1/(-L1*t10 + L1*t6 - L2*t11 - e1x*e2y - e1x*t2 + e1x*y + e1y*e2x + e1y*t8 - e1y*x + e2x*t4 - e2x*y - e2y*t9 + e2y*x - t2*t9 + t2*x + t4*t8)
    t13 = t12*(e1x*t3 - e1y*t5 - t10 + t6)
    t14 = t12*(e2x*t1 - e2y*t7 - t1*x + t11)
    t15 = -x
    J = ca.vertcat(
        ca.horzcat(t13*(e2y + t0 + t2), -t14*(e1y + t0 + t4)),
        ca.horzcat(-t13*(e2x + t15 + t8), t14*(e1x + t15 + t9)),
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
    t1 = cx + dx + t0
    t2 = -y
    t3 = ca.sin(theta2)
    t4 = L2*t3
    t5 = cy + dy + t2
    t6 = ca.cos(theta2)
    t7 = L2*t6
    t8 = ca.sin(theta1)
    t9 = ca.cos(theta1)
    t10 = t9*y
    t11 = t8*x
    t12 = 1/ca.sqrt(t1**2 + t5**2)
    t13 = L1*t8
    t14 = L1*t9
    t15 = t12/(L1*t10 - L1*t11 - e1x*e2y - e1x*t4 + e1x*y + e1y*e2x + e1y*t7 - e1y*x + e2x*t13 - e2x*y - e2y*t14 + e2y*x + t13*t7 - t14*t4 + t4*x - t7*y)
    row = ca.vertcat(
        ca.horzcat(t15*(-t1*(e2y + t2 + t4) + t5*(e2x + t0 + t7))*(e1x*t8 - e1y*t9 + t10 - t11), t15*(t1*(e1y + t13 + t2) - t5*(e1x + t0 + t14))*(e2x*t3 - e2y*t6 - t3*x + t6*y), t1*t12, t12*t5),
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
