"""Generated CasADi builders for the mechanism ``delta_linear``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/geometry.py, derivations/mechanism.py, derivations/mechanisms/delta_linear.py
inputs hash: f2759ec97f203427
sympy: 1.14.0
"""
import casadi as ca

NAME = 'delta_linear'
#: where this module was derived from: a module name, or a .py file relative to this module
DERIVATION = 'derivations.mechanisms.delta_linear'
DESCRIPTION = 'linear Delta robot (three prismatic towers, parallel rods) with a spherical-joint measuring mechanism'
POSE_NAMES = ['x', 'y', 'z']
JOINT_NAMES = ['s1', 's2', 's3']
GEOMETRY_NAMES = ['R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3', 'l1', 'l2', 'l3', 'r', 'cx', 'cy', 'cz', 'dx', 'dy', 'dz']
GEOMETRY_UNITS = {'R1': 'mm', 'R2': 'mm', 'R3': 'mm', 'phi1': 'rad', 'phi2': 'rad', 'phi3': 'rad', 'l1': 'mm', 'l2': 'mm', 'l3': 'mm', 'r': 'mm', 'cx': 'mm', 'cy': 'mm', 'cz': 'mm', 'dx': 'mm', 'dy': 'mm', 'dz': 'mm'}
JOINT_KINDS = ['prismatic', 'prismatic', 'prismatic']
POSE_UNITS = {'x': 'mm', 'y': 'mm', 'z': 'mm'}
#: (name, role, unit, target, lever arm) of each source error, in vector order
SOURCE_ERRORS = [
    ('s1', 'zero_offset', 'mm', 's1', None),
    ('s2', 'zero_offset', 'mm', 's2', None),
    ('s3', 'zero_offset', 'mm', 's3', None),
    ('R1', 'geometry', 'mm', 'R1', None),
    ('R2', 'geometry', 'mm', 'R2', None),
    ('R3', 'geometry', 'mm', 'R3', None),
    ('phi1', 'geometry', 'rad', 'phi1', 'R1'),
    ('phi2', 'geometry', 'rad', 'phi2', 'R2'),
    ('phi3', 'geometry', 'rad', 'phi3', 'R3'),
    ('l1', 'geometry', 'mm', 'l1', None),
    ('l2', 'geometry', 'mm', 'l2', None),
    ('l3', 'geometry', 'mm', 'l3', None),
    ('rMx', 'measuring', 'mm', 'cx', None),
    ('rMy', 'measuring', 'mm', 'cy', None),
    ('rMz', 'measuring', 'mm', 'cz', None),
]
SOURCE_ERROR_NAMES = ['s1', 's2', 's3', 'R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3', 'l1', 'l2', 'l3', 'rMx', 'rMy', 'rMz']
HOME_JOINTS = None
#: None (HOME_JOINTS), 'workspace centre' or the name of the function giving the home pose
HOME_POSE = 'workspace centre'
MEASURING_BASE = ['cx', 'cy', 'cz']
MEASURING_OFFSET = ['dx', 'dy', 'dz']
GAUGE_NAMES = ['translation z', 'translation x', 'translation y', 'rotation about z']
GAUGE_FIX = ['rMz', 'R1', 'phi1', 'phi2']
WORKSPACE = 'cylinder'
WORKSPACE_DEFAULTS = {'ring_azimuth': 90.0}
ALIASES = {'R': {'R1': 1.0, 'R2': 1.0, 'R3': 1.0}, 'l': {'l1': 1.0, 'l2': 1.0, 'l3': 1.0}}
LIST_ALIASES = {}
DEFAULTS = {'phi1': 90.0, 'phi2': 210.0, 'phi3': 330.0}
PARAM_SETS = {'lengths': ('l1', 'l2', 'l3'), 'base': ('R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3')}
DEFAULT_SET = ('s1', 's2', 's3', 'rMx', 'rMy')
NOISE = {'scale': 0.002, 'joint': 0.005}
POSITIVE = ['R1', 'R2', 'R3', 'l1', 'l2', 'l3', 'r']
FUNCTION_SIGNATURES = {
    'ik': ([('P', 3), ('g', 16)], [('theta', (3, 1)), ('ratio', (3, 1))]),
    'fk': ([('theta', 3), ('g', 16)], [('P', (3, 1))]),
    'transmission': ([('P', 3), ('theta', 3), ('g', 16)], [('s', (4, 1))]),
    'pose_error_jacobian': ([('P', 3), ('theta', 3), ('g', 16)], [('J_src', (3, 12))]),
    'error_jacobian': ([('P', 3), ('theta', 3), ('g', 16)], [('J', (3, 3))]),
    'measuring': ([('P', 3), ('g', 16)], [('lam', (1, 1)), ('lam_hat', (3, 1))]),
    'g_row': ([('P', 3), ('theta', 3), ('g', 16)], [('row', (1, 6))]),
    'distance': ([('theta_cmd', 3), ('g', 16), ('err', 15)], [('rho', (1, 1))]),
    'gauge': ([('g', 16)], [('Z', (15, 4))]),
    'sketch': ([('P', 3), ('theta', 3), ('g', 16)], [('segments', (3, 24))]),
}


def _ik(P, g):
    """Inverse kinematics on the chosen branch and the reach ratios (|ratio| <= 1 where reachable)."""
    x = P[0]
    y = P[1]
    z = P[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    l1 = g[6]
    l2 = g[7]
    l3 = g[8]
    r = g[9]
    t0 = -r
    t1 = R1 + t0
    t2 = (t1*ca.sin(phi1) - y)**2 + (t1*ca.cos(phi1) - x)**2
    t3 = R2 + t0
    t4 = (t3*ca.sin(phi2) - y)**2 + (t3*ca.cos(phi2) - x)**2
    t5 = R3 + t0
    t6 = (t5*ca.sin(phi3) - y)**2 + (t5*ca.cos(phi3) - x)**2
    theta = ca.vertcat(z + ca.sqrt(l1**2 - t2), z + ca.sqrt(l2**2 - t4), z + ca.sqrt(l3**2 - t6))
    ratio = ca.vertcat(ca.sqrt(t2)/l1, ca.sqrt(t4)/l2, ca.sqrt(t6)/l3)
    return (theta, ratio,)


def _fk(theta, g):
    """Forward kinematics on the chosen assembly mode."""
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    l1 = g[6]
    l2 = g[7]
    l3 = g[8]
    r = g[9]
    t0 = -r
    t1 = R1 + t0
    t2 = t1*ca.cos(phi1)
    t3 = R2 + t0
    t4 = -t2 + t3*ca.cos(phi2)
    t5 = -s1 + s2
    t6 = t1*ca.sin(phi1)
    t7 = t3*ca.sin(phi2) - t6
    t8 = t4**2 + t5**2 + t7**2
    t9 = 1/t8
    t10 = l1**2
    t11 = -l2**2 + t10 + t8
    t12 = (1/2)*t11
    t13 = t12*t9
    t14 = 1/ca.sqrt(t8)
    t15 = s1 - s3
    t16 = -t15
    t17 = t14*t5
    t18 = R3 + t0
    t19 = -t18*ca.sin(phi3) + t6
    t20 = -t19
    t21 = t14*t7
    t22 = -t18*ca.cos(phi3) + t2
    t23 = -t22
    t24 = t14*t4
    t25 = t16*t17 + t20*t21 + t23*t24
    t26 = -t15 - t17*t25
    t27 = -t19 - t21*t25
    t28 = -t22 - t24*t25
    t29 = 1/ca.sqrt(t26**2 + t27**2 + t28**2)
    t30 = t26*t29
    t31 = t16*t30
    t32 = t27*t29
    t33 = t20*t32
    t34 = t28*t29
    t35 = t23*t34
    t36 = t31 + t33 + t35
    t37 = -t12*t14*t25/t36 + (-l3**2 + t10 + t25**2 + t36**2)/(2*t31 + 2*t33 + 2*t35)
    t38 = t14*t27*t29*t4 - t21*t34
    t39 = ca.sqrt(t10 - 1/4*t11**2*t9 - t37**2)*ca.sign(t38)
    P = ca.vertcat(t13*t4 + t2 + t34*t37 - t39*(t14*t26*t29*t7 - t17*t32), t13*t7 + t32*t37 - t39*(t17*t34 - t24*t30) + t6, s1 + t13*t5 + t30*t37 - t38*t39)
    return (P,)


def _transmission(P, theta, g):
    """Singularity indicators: |s| >= margin away from a singular configuration."""
    x = P[0]
    y = P[1]
    z = P[2]
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    l1 = g[6]
    l2 = g[7]
    l3 = g[8]
    r = g[9]
    t0 = 1/l1
    t1 = -z
    t2 = 1/l2
    t3 = 1/l3
    t4 = s2*x
    t5 = ca.sin(phi1)
    t6 = R1*t5
    t7 = ca.cos(phi1)
    t8 = t7*y
    t9 = R1*t8
    t10 = s1*y
    t11 = ca.cos(phi2)
    t12 = R2*t11
    t13 = ca.sin(phi2)
    t14 = t13*x
    t15 = R2*t14
    t16 = ca.sin(phi3)
    t17 = R3*t16
    t18 = s1*x
    t19 = ca.cos(phi3)
    t20 = R3*t19
    t21 = s2*y
    t22 = r*t14
    t23 = r*t10
    t24 = r*t16
    t25 = r*t8
    t26 = r*s3
    t27 = t26*t5
    t28 = t11*t26
    t29 = s3*t6
    t30 = r*t5
    t31 = r*t19
    t32 = t7*z
    t33 = R1*t13
    t34 = R2*t33
    t35 = s2*t7
    t36 = R1*t17
    t37 = t6*z
    t38 = s2*t6
    t39 = t26*t7
    t40 = r*t11
    t41 = R1*t24
    t42 = R2*t13
    t43 = t20*t42
    t44 = t12*z
    t45 = s1*t12
    t46 = t31*t42
    t47 = t17*t40
    t48 = t20*t30
    t49 = r*t13*t20
    t50 = r*t32
    t51 = r**2
    t52 = t13*t51
    t53 = t19*t52
    t54 = t16*t51
    t55 = t5*t51
    t56 = t11*t55
    t57 = t19*t55
    t58 = t52*t7
    t59 = t11*t54
    s = ca.vertcat(-t0*(-s1 - t1), -t2*(-s2 - t1), -t3*(-s3 - t1), t0*t2*t3*(-r*t17*t35 - s1*t15 + s1*t22 + s1*t43 - s1*t46 + s1*t47 - s1*t49 + s1*t53 - s1*t59 + s2*t25 + s2*t48 - s2*t57 - s2*t9 - s3*t12*y + s3*t15 - s3*t22 - s3*t25 - s3*t34*t7 + s3*t56 - s3*t58 + s3*t9 + t10*t12 - t10*t20 - t11*t23 - t12*t27 + t12*t29 - t12*t37 + t17*t18 - t17*t4 + t17*t44 - t17*t45 + t17*t50 - t18*t24 + t19*t23 + t20*t21 + t20*t37 - t20*t38 - t21*t31 + t24*t4 - t24*t44 + t24*t45 + t27*x - t28*t6 + t28*y - t29*x - t30*t4 + t30*t44 - t31*t37 + t31*t38 + t32*t34 - t32*t36 + t32*t41 - t32*t54 + t33*t39 - t33*t50 + t35*t36 - t35*t41 + t35*t54 + t37*t40 + t39*t42 + t4*t6 - t42*t50 - t43*z + t46*z - t47*z - t48*z + t49*z - t53*z - t56*z + t57*z + t58*z + t59*z))
    return (s,)


def _pose_error_jacobian(P, theta, g):
    """dP/d(robot source errors s1 s2 s3 R1 R2 R3 phi1 phi2 phi3 l1 l2 l3), per rad or mm (implicit differentiation)."""
    x = P[0]
    y = P[1]
    z = P[2]
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    l1 = g[6]
    l2 = g[7]
    l3 = g[8]
    r = g[9]
    t0 = -2*z
    t1 = 2*s1 + t0
    t2 = ca.sin(phi1)
    t3 = R1*t2
    t4 = 8*x
    t5 = ca.cos(phi1)
    t6 = R1*t5
    t7 = s2*t6
    t8 = 8*y
    t9 = R1*s3
    t10 = t2*t4
    t11 = t5*t8
    t12 = ca.sin(phi2)
    t13 = R2*t12
    t14 = t13*t4
    t15 = ca.cos(phi2)
    t16 = R2*t15
    t17 = s3*t8
    t18 = R3*s1
    t19 = ca.sin(phi3)
    t20 = t19*t4
    t21 = ca.cos(phi3)
    t22 = t21*t8
    t23 = R3*s2
    t24 = r*s1
    t25 = r*s2
    t26 = r*s3
    t27 = s3*t12
    t28 = r*t17
    t29 = 8*t2
    t30 = t29*t9
    t31 = 8*t13
    t32 = t31*t5
    t33 = R2*z
    t34 = 8*t3
    t35 = t15*t34
    t36 = 8*t6
    t37 = t12*t36
    t38 = t21*t34
    t39 = 8*t19
    t40 = t39*t6
    t41 = R3*t21
    t42 = R3*t19
    t43 = r*t15
    t44 = r*t5
    t45 = 8*t12
    t46 = r*z
    t47 = t21*t31
    t48 = t16*t39
    t49 = t33*t45
    t50 = 8*t15*t42
    t51 = t33*t43
    t52 = r*t21
    t53 = t41*t46
    t54 = r**2
    t55 = t21*t54
    t56 = 8*t55
    t57 = t15*t54
    t58 = t39*t57
    t59 = t29*t55
    t60 = t5*t54
    t61 = t39*t60
    t62 = t29*t57
    t63 = 8*t60
    t64 = t12*z
    t65 = 1/(-r*t27*t4 + s1*t12*t56 - s1*t14 + s1*t16*t8 - s1*t58 + s2*t3*t4 - s2*t59 + s2*t61 + s3*t14 + s3*t62 - t10*t25 + t10*t26 - t10*t9 + t11*t25 + t11*t9 + t12*t24*t4 - t15*t24*t8 + t15*t28 - t16*t17 - t16*t26*t29 + t16*t30 + t18*t20 - t18*t22 + t18*t39*t43 - t18*t45*t52 + t18*t47 - t18*t48 - t20*t23 - t20*t24 + t20*t25 + t22*t23 + t22*t24 - t22*t25 + t23*t29*t52 - t23*t38 - t23*t39*t44 + t23*t40 - t24*t47 + t24*t48 + t25*t38 - t25*t40 + t26*t32 - t27*t63 - t28*t5 + t29*t51 - t29*t53 - t30*t43 - t32*t9 - t33*t35 + t33*t37 + t33*t50 + t34*t41*z + t35*t46 - t36*t42*z - t37*t46 - t38*t46 - t39*t51 + t40*t46 - t41*t49 + 8*t42*t46*t5 + t44*t45*t9 - t44*t49 + t45*t53 - t46*t50 + t49*t52 - t56*t64 + t58*z + t59*z - t61*z - t62*z + t63*t64 - t7*t8)
    t66 = 4*y
    t67 = s2*t66
    t68 = 4*t12
    t69 = t33*t68
    t70 = 4*t19
    t71 = s3*t68
    t72 = r*t70
    t73 = t46*t68
    t74 = t70*z
    t75 = R3*t74 - r*t74 - s3*t66
    t76 = t65*(R2*t71 - r*t71 + s2*t72 - t23*t70 + t67 - t69 + t73 + t75)
    t77 = 2*s2 + t0
    t78 = 4*t2
    t79 = R1*t78
    t80 = s1*t66 + t46*t78 - t79*z
    t81 = t65*(4*R3*s1*t19 + 4*r*s3*t2 - s1*t72 - t75 - t78*t9 - t80)
    t82 = 2*s3 + t0
    t83 = s1*t68
    t84 = r*t78
    t85 = t65*(-R2*t83 + r*t83 + s2*t79 - s2*t84 - t67 + t69 - t73 + t80)
    t86 = 2*x
    t87 = 2*y
    t88 = t2**2
    t89 = t5**2
    t90 = 2*r
    t91 = 2*R1*t88 + 2*R1*t89 - t2*t87 - t5*t86 - t88*t90 - t89*t90
    t92 = t12**2
    t93 = t15**2
    t94 = 2*R2*t92 + 2*R2*t93 - t12*t87 - t15*t86 - t90*t92 - t90*t93
    t95 = t19**2
    t96 = t21**2
    t97 = 2*R3*t95 + 2*R3*t96 - t19*t87 - t21*t86 - t90*t95 - t90*t96
    t98 = t90*x
    t99 = t90*y
    t100 = -t2*t98 + t3*t86 + t5*t99 - t6*t87
    t101 = -t12*t98 + t13*t86 + t15*t99 - t16*t87
    t102 = -t19*t98 + t21*t99 - t41*t87 + t42*t86
    t103 = 2*l1
    t104 = 2*l2
    t105 = 2*l3
    t106 = 4*x
    t107 = s2*t106
    t108 = 4*t15
    t109 = t108*t33
    t110 = 4*s3
    t111 = 4*t21
    t112 = t108*t46
    t113 = 4*z
    t114 = -s3*t106 - t111*t46 + t113*t41
    t115 = t65*(4*R3*s2*t21 + 4*r*s3*t15 - t107 + t109 - t110*t16 - t111*t25 - t112 - t114)
    t116 = 4*t5
    t117 = s1*t106 - t113*t6 + t116*t46
    t118 = t65*(-r*t110*t5 - t111*t18 + t111*t24 + t114 + t116*t9 + t117)
    t119 = t65*(4*R2*s1*t15 + 4*r*s2*t5 + t107 - t108*t24 - t109 + t112 - t117 - 4*t7)
    t120 = t106*t13
    t121 = r*t66
    t122 = t121*t15
    t123 = t16*t66
    t124 = r*t106
    t125 = t12*t124
    t126 = R2*t68
    t127 = R3*t72
    t128 = t106*t42 + t121*t21 - t124*t19 - t41*t66
    t129 = t65*(4*R2*R3*t15*t19 + 4*R2*r*t12*t21 + 4*R3*r*t12*t21 + t120 + t122 - t123 - t125 - t126*t41 - t127*t15 - t128 + 4*t15*t19*t54 - t16*t72 - t55*t68)
    t130 = -t106*t3 - t121*t5 + t124*t2 + t6*t66
    t131 = t65*(-R3*t6*t70 + t127*t5 + t128 + t130 + t41*t79 - t41*t84 - t5*t54*t70 - t52*t79 + t55*t78 + t6*t72)
    t132 = t65*(4*R1*R2*t12*t5 + 4*R1*r*t15*t2 + 4*R2*r*t15*t2 - r*t6*t68 + 4*t12*t5*t54 - t120 - t122 + t123 + t125 - t126*t44 - t130 - t16*t79 - t57*t78)
    J_src = ca.vertcat(
        ca.horzcat(-t1*t76, -t77*t81, -t82*t85, -t76*t91, -t81*t94, -t85*t97, -t100*t76, -t101*t81, -t102*t85, t103*t76, t104*t81, t105*t85),
        ca.horzcat(-t1*t115, -t118*t77, -t119*t82, -t115*t91, -t118*t94, -t119*t97, -t100*t115, -t101*t118, -t102*t119, t103*t115, t104*t118, t105*t119),
        ca.horzcat(-t1*t129, -t131*t77, -t132*t82, -t129*t91, -t131*t94, -t132*t97, -t100*t129, -t101*t131, -t102*t132, t103*t129, t104*t131, t105*t132),
    )
    return (J_src,)


def _error_jacobian(P, theta, g):
    """dP/d(offsets as lengths: lever_i dtheta_i for a revolute joint, ds_i for a prismatic one) (paper Eq. 13 in n dimensions)."""
    x = P[0]
    y = P[1]
    z = P[2]
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    r = g[9]
    t0 = 4*y
    t1 = s2*t0
    t2 = ca.sin(phi2)
    t3 = 4*t2
    t4 = R2*z
    t5 = t3*t4
    t6 = ca.sin(phi3)
    t7 = 4*t6
    t8 = R3*s2
    t9 = s3*t3
    t10 = r*t7
    t11 = r*z
    t12 = t11*t3
    t13 = t7*z
    t14 = R3*t13 - r*t13 - s3*t0
    t15 = ca.sin(phi1)
    t16 = 8*x
    t17 = t15*t16
    t18 = 8*y
    t19 = ca.cos(phi1)
    t20 = R1*t19
    t21 = R1*s3
    t22 = t18*t19
    t23 = s1*t16
    t24 = R2*t2
    t25 = ca.cos(phi2)
    t26 = t18*t25
    t27 = s1*t26
    t28 = R2*s3
    t29 = t16*t2
    t30 = R3*s1
    t31 = t16*t6
    t32 = ca.cos(phi3)
    t33 = t18*t32
    t34 = r*t23
    t35 = r*s1
    t36 = r*s2
    t37 = r*s3
    t38 = R2*t25
    t39 = 8*t15
    t40 = t21*t39
    t41 = 8*t24
    t42 = t19*t21
    t43 = R1*t39
    t44 = t25*t4
    t45 = 8*t2
    t46 = t20*t45
    t47 = t32*t43
    t48 = 8*t6
    t49 = t20*t48
    t50 = R3*z
    t51 = r*t25
    t52 = r*t45
    t53 = t11*t25
    t54 = t32*t41
    t55 = t38*t48
    t56 = R3*t32
    t57 = t4*t45
    t58 = t44*t48
    t59 = r*t19
    t60 = r*t39
    t61 = t11*t56
    t62 = R3*t19
    t63 = r**2
    t64 = t32*t63
    t65 = t45*t64
    t66 = t25*t63
    t67 = t48*t66
    t68 = t39*t64
    t69 = t19*t63
    t70 = t48*t69
    t71 = t39*t66
    t72 = t45*t69
    t73 = 1/(R1*s2*t17 + R2*t27 - R3*t48*t53 + R3*t58 - r*t27 + r*t32*t57 - r*t58 + s1*t65 - s1*t67 - s2*t18*t20 - s2*t68 + s2*t70 + s3*t71 - s3*t72 - t11*t46 - t11*t47 + t11*t48*t62 + t11*t49 - t17*t21 - t17*t36 + t17*t37 + t2*t34 + t21*t22 + t22*t36 - t22*t37 - t23*t24 - t26*t28 + t26*t37 + t28*t29 - t28*t39*t51 + t28*t45*t59 - t29*t37 + t30*t31 - t30*t32*t52 - t30*t33 + t30*t48*t51 + t30*t54 - t30*t55 + t31*t36 - t31*t8 + t32*t60*t8 + t33*t35 - t33*t36 + t33*t8 - t34*t6 - t35*t54 + t35*t55 + t36*t47 - t36*t49 + t38*t40 - t39*t61 + t4*t46 - t40*t51 - t41*t42 + t42*t52 - t43*t44 + t43*t53 + t44*t60 + t45*t61 + t47*t50 - t47*t8 - t48*t59*t8 - t49*t50 + t49*t8 - t56*t57 - t57*t59 - t65*z + t67*z + t68*z - t70*z - t71*z + t72*z)
    t74 = -2*z
    t75 = t73*(2*s1 + t74)
    t76 = 4*t15
    t77 = R1*t76
    t78 = s1*t0 + t11*t76 - t77*z
    t79 = t73*(2*s2 + t74)
    t80 = s1*t3
    t81 = r*t76
    t82 = t73*(2*s3 + t74)
    t83 = 4*x
    t84 = s2*t83
    t85 = 4*t25
    t86 = t4*t85
    t87 = 4*t32
    t88 = r*t87
    t89 = t11*t85
    t90 = -s3*t83 - t11*t87 + t50*t87
    t91 = 4*t19
    t92 = R1*t91
    t93 = s1*t83 + t11*t91 - t92*z
    t94 = t2*t83
    t95 = R2*t94
    t96 = t0*t25
    t97 = r*t96
    t98 = R2*t96
    t99 = r*t94
    t100 = t10*t25
    t101 = t0*t32
    t102 = t6*t83
    t103 = -R3*t101 + R3*t102 + r*t101 - r*t102
    t104 = t32*t77
    t105 = t15*t83
    t106 = t0*t19
    t107 = -R1*t105 + R1*t106 + r*t105 - r*t106
    t108 = r*t3
    J = ca.vertcat(
        ca.horzcat(-t75*(R2*t9 - r*t9 + s2*t10 + t1 + t12 + t14 - t5 - t7*t8), -t79*(4*R3*s1*t6 + 4*r*s3*t15 - s1*t10 - t14 - t21*t76 - t78), -t82*(-R2*t80 + r*t80 + s2*t77 - s2*t81 - t1 - t12 + t5 + t78)),
        ca.horzcat(-t75*(4*R3*s2*t32 + 4*r*s3*t25 - s2*t88 - t28*t85 - t84 + t86 - t89 - t90), -t79*(s1*t88 + t21*t91 - t30*t87 - t37*t91 + t90 + t93), -t82*(4*R2*s1*t25 - r*s1*t85 + 4*r*s2*t19 - s2*t92 + t84 - t86 + t89 - t93)),
        ca.horzcat(-t75*(4*R2*R3*t25*t6 - R2*R3*t3*t32 + 4*R2*r*t2*t32 - R2*t100 + 4*R3*r*t2*t32 - R3*t100 - t103 + 4*t25*t6*t63 - t3*t64 + t95 + t97 - t98 - t99), -t79*(R3*t104 - R3*t20*t7 - r*t104 + t10*t20 + t10*t62 + t103 + t107 - t19*t63*t7 - t56*t81 + t64*t76), -t82*(4*R1*R2*t19*t2 + 4*R1*r*t15*t25 + 4*R2*r*t15*t25 - R2*t108*t19 - R2*t25*t77 - t107 - t108*t20 + 4*t19*t2*t63 - t66*t76 - t95 - t97 + t98 + t99)),
    )
    return (J,)


def _measuring(P, g):
    """Nominal measuring-mechanism length |O2 - O1| and its unit vector."""
    x = P[0]
    y = P[1]
    z = P[2]
    cx = g[10]
    cy = g[11]
    cz = g[12]
    dx = g[13]
    dy = g[14]
    dz = g[15]
    t0 = -cx + dx + x
    t1 = -cy + dy + y
    t2 = -cz + dz + z
    t3 = ca.sqrt(t0**2 + t1**2 + t2**2)
    t4 = 1/t3
    lam = ca.vertcat(t3)
    lam_hat = ca.vertcat(t0*t4, t1*t4, t2*t4)
    return (lam, lam_hat,)


def _g_row(P, theta, g):
    """Identification row g_k = d rho / d(offsets as lengths, measuring errors) (paper Eq. 28: lam_hat^T [J, -I] for lambda = P - c - d)."""
    x = P[0]
    y = P[1]
    z = P[2]
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    r = g[9]
    cx = g[10]
    cy = g[11]
    cz = g[12]
    dx = g[13]
    dy = g[14]
    dz = g[15]
    t0 = 4*y
    t1 = s2*t0
    t2 = ca.sin(phi2)
    t3 = 4*t2
    t4 = R2*z
    t5 = t3*t4
    t6 = ca.sin(phi3)
    t7 = 4*t6
    t8 = R3*s2
    t9 = s3*t3
    t10 = r*s2
    t11 = r*z
    t12 = t11*t3
    t13 = t7*z
    t14 = R3*t13 - r*t13 - s3*t0
    t15 = -cx + dx + x
    t16 = -cy + dy + y
    t17 = -cz + dz + z
    t18 = 1/ca.sqrt(t15**2 + t16**2 + t17**2)
    t19 = t15*t18
    t20 = R1*s2
    t21 = ca.sin(phi1)
    t22 = 8*x
    t23 = t21*t22
    t24 = ca.cos(phi1)
    t25 = 8*y
    t26 = t24*t25
    t27 = R1*s3
    t28 = s1*t22
    t29 = t2*t28
    t30 = ca.cos(phi2)
    t31 = t25*t30
    t32 = s1*t31
    t33 = R2*s3
    t34 = t2*t22
    t35 = t28*t6
    t36 = ca.cos(phi3)
    t37 = t25*t36
    t38 = R3*s1
    t39 = t22*t6
    t40 = r*s1
    t41 = r*s3
    t42 = 8*R1
    t43 = t21*t42
    t44 = t30*t43
    t45 = t24*t42
    t46 = t2*t45
    t47 = t30*t4
    t48 = t36*t43
    t49 = t45*t6
    t50 = R3*z
    t51 = 8*R2
    t52 = t38*t51
    t53 = t2*t36
    t54 = t30*t6
    t55 = 8*R3
    t56 = t4*t53
    t57 = t47*t6
    t58 = t40*t51
    t59 = 8*r
    t60 = t33*t59
    t61 = t24*t59
    t62 = t38*t59
    t63 = t21*t36
    t64 = t11*t55
    t65 = r**2
    t66 = 8*t65
    t67 = t2*t66
    t68 = t36*t67
    t69 = t6*t66
    t70 = t30*t69
    t71 = t21*t65
    t72 = 8*t71
    t73 = t36*t72
    t74 = t24*t69
    t75 = t30*t72
    t76 = t24*t67
    t77 = 1/(-R2*t29 + R2*t32 + R3*t35 + r*t29 - r*t32 - r*t35 + s1*t68 - s1*t70 - s2*t73 + s2*t74 + s3*t75 - s3*t76 - t10*t23 + t10*t26 - t10*t37 + t10*t39 + t10*t48 - t10*t49 + t11*t44 - t11*t46 - t11*t48 + t11*t49 + t2*t24*t60 - t2*t4*t61 + t20*t23 - t20*t26 - t21*t30*t60 + t21*t47*t59 - t23*t27 + t23*t41 + t24*t6*t64 + t26*t27 - t26*t41 - t31*t33 + t31*t41 + t33*t34 + t33*t44 - t33*t46 - t34*t41 - t37*t38 + t37*t40 + t37*t8 - t39*t8 + t4*t46 - t41*t44 + t41*t46 - t43*t47 + t48*t50 - t48*t8 - t49*t50 + t49*t8 + t52*t53 - t52*t54 - t53*t58 - t53*t62 + t53*t64 + t54*t58 + t54*t62 - t54*t64 - t55*t56 + t55*t57 + t56*t59 - t57*t59 + t59*t63*t8 - t6*t61*t8 - t63*t64 - t68*z + t70*z + t73*z - t74*z - t75*z + t76*z)
    t78 = -2*z
    t79 = t77*(2*s1 + t78)
    t80 = 4*x
    t81 = s2*t80
    t82 = 4*t30
    t83 = t4*t82
    t84 = 4*t36
    t85 = t11*t82
    t86 = -s3*t80 - t11*t84 + t50*t84
    t87 = t16*t18
    t88 = t2*t80
    t89 = R2*t88
    t90 = t0*t30
    t91 = r*t90
    t92 = R2*t90
    t93 = r*t88
    t94 = t30*t7
    t95 = R2*r
    t96 = R3*r
    t97 = t0*t36
    t98 = t6*t80
    t99 = -R3*t97 + R3*t98 + r*t97 - r*t98
    t100 = t17*t18
    t101 = 4*t21
    t102 = R1*z
    t103 = s1*t0 - t101*t102 + t101*t11
    t104 = t77*(2*s2 + t78)
    t105 = s1*t84
    t106 = 4*t24
    t107 = s1*t80 - t102*t106 + t106*t11
    t108 = R1*R3
    t109 = t24*t7
    t110 = t21*t84
    t111 = R1*r
    t112 = t21*t80
    t113 = t0*t24
    t114 = -R1*t112 + R1*t113 + r*t112 - r*t113
    t115 = s1*t3
    t116 = t77*(2*s3 + t78)
    t117 = t24*t3
    row = ca.vertcat(
        ca.horzcat(-t100*t79*(-R2*R3*t3*t36 + 4*R2*R3*t30*t6 + 4*R2*r*t2*t36 + 4*R3*r*t2*t36 - t3*t36*t65 + 4*t30*t6*t65 + t89 + t91 - t92 - t93 - t94*t95 - t94*t96 - t99) - t19*t79*(R2*t9 - r*t9 + t1 + t10*t7 + t12 + t14 - t5 - t7*t8) - t79*t87*(4*R3*s2*t36 + 4*r*s3*t30 - t10*t84 - t33*t82 - t81 + t83 - t85 - t86), -t100*t104*(-t108*t109 + t108*t110 + t109*t111 + t109*t96 - t110*t111 - t110*t96 + t114 - t24*t65*t7 + t71*t84 + t99) - t104*t19*(4*R3*s1*t6 - r*s1*t7 + 4*r*s3*t21 - t101*t27 - t103 - t14) - t104*t87*(-R3*t105 + r*t105 + t106*t27 - t106*t41 + t107 + t86), -t100*t116*(4*R1*R2*t2*t24 - R1*R2*t21*t82 + 4*R1*r*t21*t30 + 4*R2*r*t21*t30 - t111*t117 - t114 - t117*t95 + 4*t2*t24*t65 - t71*t82 - t89 - t91 + t92 + t93) - t116*t19*(-R2*t115 + r*t115 - t1 - t10*t101 + t101*t20 + t103 - t12 + t5) - t116*t87*(4*R2*s1*t30 - r*s1*t82 + 4*r*s2*t24 - t106*t20 - t107 + t81 - t83 + t85), -t19, -t87, -t100),
    )
    return (row,)


def _distance(theta_cmd, g, err):
    """Exact distance O1'O2' for commanded joints, nominal geometry and source errors."""
    s1 = theta_cmd[0]
    s2 = theta_cmd[1]
    s3 = theta_cmd[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    l1 = g[6]
    l2 = g[7]
    l3 = g[8]
    r = g[9]
    cx = g[10]
    cy = g[11]
    cz = g[12]
    dx = g[13]
    dy = g[14]
    dz = g[15]
    d_s1 = err[0]
    d_s2 = err[1]
    d_s3 = err[2]
    d_R1 = err[3]
    d_R2 = err[4]
    d_R3 = err[5]
    d_phi1 = err[6]
    d_phi2 = err[7]
    d_phi3 = err[8]
    d_l1 = err[9]
    d_l2 = err[10]
    d_l3 = err[11]
    d_rMx = err[12]
    d_rMy = err[13]
    d_rMz = err[14]
    t0 = d_s1 + s1
    t1 = d_s2 + s2 - t0
    t2 = d_phi1 + phi1
    t3 = -r
    t4 = R1 + d_R1 + t3
    t5 = t4*ca.sin(t2)
    t6 = d_phi2 + phi2
    t7 = R2 + d_R2 + t3
    t8 = -t5 + t7*ca.sin(t6)
    t9 = t4*ca.cos(t2)
    t10 = t7*ca.cos(t6) - t9
    t11 = t1**2 + t10**2 + t8**2
    t12 = 1/ca.sqrt(t11)
    t13 = -d_s3 - s3 + t0
    t14 = -t13
    t15 = t1*t12
    t16 = d_phi3 + phi3
    t17 = R3 + d_R3 + t3
    t18 = -t17*ca.sin(t16) + t5
    t19 = -t18
    t20 = t12*t8
    t21 = -t17*ca.cos(t16) + t9
    t22 = -t21
    t23 = t10*t12
    t24 = t14*t15 + t19*t20 + t22*t23
    t25 = -t13 - t15*t24
    t26 = -t18 - t20*t24
    t27 = -t21 - t23*t24
    t28 = 1/ca.sqrt(t25**2 + t26**2 + t27**2)
    t29 = t25*t28
    t30 = t14*t29
    t31 = t26*t28
    t32 = t19*t31
    t33 = t27*t28
    t34 = t22*t33
    t35 = t30 + t32 + t34
    t36 = (d_l1 + l1)**2
    t37 = t11 + t36 - (d_l2 + l2)**2
    t38 = (1/2)*t37
    t39 = -t12*t24*t38/t35 + (t24**2 + t35**2 + t36 - (d_l3 + l3)**2)/(2*t30 + 2*t32 + 2*t34)
    t40 = 1/t11
    t41 = t38*t40
    t42 = t10*t12*t26*t28 - t20*t33
    t43 = ca.sqrt(t36 - 1/4*t37**2*t40 - t39**2)*ca.sign(t42)
    rho = ca.vertcat(ca.sqrt((-cx - d_rMx + dx + t10*t41 + t33*t39 - t43*(-t15*t31 + t20*t29) + t9)**2 + (-cy - d_rMy + dy + t31*t39 + t41*t8 - t43*(t1*t12*t27*t28 - t23*t29) + t5)**2 + (-cz - d_rMz + dz + t0 + t1*t41 + t29*t39 - t42*t43)**2))
    return (rho,)


def _gauge(g):
    """Gauge motions (columns): source-error directions no distance change can see."""
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    r = g[9]
    cx = g[10]
    cy = g[11]
    dx = g[13]
    dy = g[14]
    t0 = ca.cos(phi1)
    t1 = ca.sin(phi1)
    t2 = ca.cos(phi2)
    t3 = ca.sin(phi2)
    t4 = ca.cos(phi3)
    t5 = ca.sin(phi3)
    t6 = -r
    t7 = 1/(R1 + t6)
    t8 = 1/(R2 + t6)
    t9 = 1/(R3 + t6)
    Z = ca.vertcat(
        ca.horzcat(1, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0),
        ca.horzcat(0, t0, t1, 0),
        ca.horzcat(0, t2, t3, 0),
        ca.horzcat(0, t4, t5, 0),
        ca.horzcat(0, -t1*t7, t0*t7, 1),
        ca.horzcat(0, -t3*t8, t2*t8, 1),
        ca.horzcat(0, -t5*t9, t4*t9, 1),
        ca.horzcat(0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -cy + dy),
        ca.horzcat(0, 0, 1, cx - dx),
        ca.horzcat(1, 0, 0, 0),
    )
    return (Z,)


def _sketch(P, theta, g):
    """The robot drawn as line segments (columns 2k and 2k+1: the ends of segment k), mm."""
    x = P[0]
    y = P[1]
    z = P[2]
    s1 = theta[0]
    s2 = theta[1]
    s3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    r = g[9]
    t0 = ca.cos(phi1)
    t1 = R1*t0
    t2 = ca.cos(phi2)
    t3 = R2*t2
    t4 = ca.cos(phi3)
    t5 = R3*t4
    t6 = r*t0 + x
    t7 = r*t2 + x
    t8 = r*t4 + x
    t9 = ca.sin(phi1)
    t10 = R1*t9
    t11 = ca.sin(phi2)
    t12 = R2*t11
    t13 = ca.sin(phi3)
    t14 = R3*t13
    t15 = r*t9 + y
    t16 = r*t11 + y
    t17 = r*t13 + y
    segments = ca.vertcat(
        ca.horzcat(t1, t3, t3, t5, t5, t1, t1, t1, t1, t6, t3, t3, t3, t7, t5, t5, t5, t8, t6, t7, t7, t8, t8, t6),
        ca.horzcat(t10, t12, t12, t14, t14, t10, t10, t10, t10, t15, t12, t12, t12, t16, t14, t14, t14, t17, t15, t16, t16, t17, t17, t15),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, s1, s1, z, 0, s2, s2, z, 0, s3, s3, z, z, z, z, z, z, z),
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
