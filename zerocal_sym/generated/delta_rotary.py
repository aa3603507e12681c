"""Generated CasADi builders for the mechanism ``delta_rotary``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/geometry.py, derivations/mechanism.py, derivations/mechanisms/delta_rotary.py
inputs hash: 5f39c70e19cfaf00
sympy: 1.14.0
"""
import casadi as ca

NAME = 'delta_rotary'
#: where this module was derived from: a module name, or a .py file relative to this module
DERIVATION = 'derivations.mechanisms.delta_rotary'
DESCRIPTION = 'rotary Delta robot (three RSS limbs, parallelogram forearms) with a spherical-joint measuring mechanism'
POSE_NAMES = ['x', 'y', 'z']
JOINT_NAMES = ['theta1', 'theta2', 'theta3']
GEOMETRY_NAMES = ['R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3', 'z1', 'z2', 'z3', 'L1', 'L2', 'L3', 'l1', 'l2', 'l3', 'r', 'cx', 'cy', 'cz', 'dx', 'dy', 'dz']
GEOMETRY_UNITS = {'R1': 'mm', 'R2': 'mm', 'R3': 'mm', 'phi1': 'rad', 'phi2': 'rad', 'phi3': 'rad', 'z1': 'mm', 'z2': 'mm', 'z3': 'mm', 'L1': 'mm', 'L2': 'mm', 'L3': 'mm', 'l1': 'mm', 'l2': 'mm', 'l3': 'mm', 'r': 'mm', 'cx': 'mm', 'cy': 'mm', 'cz': 'mm', 'dx': 'mm', 'dy': 'mm', 'dz': 'mm'}
JOINT_KINDS = ['revolute', 'revolute', 'revolute']
POSE_UNITS = {'x': 'mm', 'y': 'mm', 'z': 'mm'}
#: (name, role, unit, target, lever arm) of each source error, in vector order
SOURCE_ERRORS = [
    ('theta1', 'zero_offset', 'rad', 'theta1', 'L1'),
    ('theta2', 'zero_offset', 'rad', 'theta2', 'L2'),
    ('theta3', 'zero_offset', 'rad', 'theta3', 'L3'),
    ('R1', 'geometry', 'mm', 'R1', None),
    ('R2', 'geometry', 'mm', 'R2', None),
    ('R3', 'geometry', 'mm', 'R3', None),
    ('phi1', 'geometry', 'rad', 'phi1', 'R1'),
    ('phi2', 'geometry', 'rad', 'phi2', 'R2'),
    ('phi3', 'geometry', 'rad', 'phi3', 'R3'),
    ('z1', 'geometry', 'mm', 'z1', None),
    ('z2', 'geometry', 'mm', 'z2', None),
    ('z3', 'geometry', 'mm', 'z3', None),
    ('L1', 'geometry', 'mm', 'L1', None),
    ('L2', 'geometry', 'mm', 'L2', None),
    ('L3', 'geometry', 'mm', 'L3', None),
    ('l1', 'geometry', 'mm', 'l1', None),
    ('l2', 'geometry', 'mm', 'l2', None),
    ('l3', 'geometry', 'mm', 'l3', None),
    ('rMx', 'measuring', 'mm', 'cx', None),
    ('rMy', 'measuring', 'mm', 'cy', None),
    ('rMz', 'measuring', 'mm', 'cz', None),
]
SOURCE_ERROR_NAMES = ['theta1', 'theta2', 'theta3', 'R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3', 'z1', 'z2', 'z3', 'L1', 'L2', 'L3', 'l1', 'l2', 'l3', 'rMx', 'rMy', 'rMz']
HOME_JOINTS = [0.0, 0.0, 0.0]
#: None (HOME_JOINTS), 'workspace centre' or the name of the function giving the home pose
HOME_POSE = None
MEASURING_BASE = ['cx', 'cy', 'cz']
MEASURING_OFFSET = ['dx', 'dy', 'dz']
GAUGE_NAMES = ['translation z', 'rotation about z']
GAUGE_FIX = ['z1', 'phi1']
WORKSPACE = 'cylinder'
WORKSPACE_DEFAULTS = {}
ALIASES = {'R': {'R1': 1.0, 'R2': 1.0, 'R3': 1.0}, 'L': {'L1': 1.0, 'L2': 1.0, 'L3': 1.0}, 'l': {'l1': 1.0, 'l2': 1.0, 'l3': 1.0}}
LIST_ALIASES = {}
DEFAULTS = {'phi1': 0.0, 'phi2': 120.0, 'phi3': 240.0, 'z1': 0.0, 'z2': 0.0, 'z3': 0.0}
PARAM_SETS = {'lengths': ('L1', 'L2', 'L3', 'l1', 'l2', 'l3'), 'base': ('R1', 'R2', 'R3', 'phi1', 'phi2', 'phi3', 'z1', 'z2', 'z3')}
DEFAULT_SET = ('theta1', 'theta2', 'theta3', 'rMx', 'rMy', 'rMz')
NOISE = {}
POSITIVE = ['R1', 'R2', 'R3', 'L1', 'L2', 'L3', 'l1', 'l2', 'l3', 'r']
FUNCTION_SIGNATURES = {
    'ik': ([('P', 3), ('g', 22)], [('theta', (3, 1)), ('ratio', (3, 1))]),
    'fk': ([('theta', 3), ('g', 22)], [('P', (3, 1))]),
    'transmission': ([('P', 3), ('theta', 3), ('g', 22)], [('s', (4, 1))]),
    'pose_error_jacobian': ([('P', 3), ('theta', 3), ('g', 22)], [('J_src', (3, 18))]),
    'error_jacobian': ([('P', 3), ('theta', 3), ('g', 22)], [('J', (3, 3))]),
    'measuring': ([('P', 3), ('g', 22)], [('lam', (1, 1)), ('lam_hat', (3, 1))]),
    'g_row': ([('P', 3), ('theta', 3), ('g', 22)], [('row', (1, 6))]),
    'distance': ([('theta_cmd', 3), ('g', 22), ('err', 21)], [('rho', (1, 1))]),
    'gauge': ([('g', 22)], [('Z', (21, 2))]),
    'sketch': ([('P', 3), ('theta', 3), ('g', 22)], [('segments', (3, 24))]),
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
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    l1 = g[12]
    l2 = g[13]
    l3 = g[14]
    r = g[15]
    t0 = z - z1
    t1 = -t0
    t2 = ca.sin(phi1)
    t3 = -R1*t2 + r*t2 + y
    t4 = ca.cos(phi1)
    t5 = -R1*t4 + r*t4 + x
    t6 = t2*t3 + t4*t5
    t7 = (1/2)*(L1**2 - l1**2 + t0**2 + t3**2 + t5**2)/(L1*ca.sqrt(t1**2 + t6**2))
    t8 = z - z2
    t9 = -t8
    t10 = ca.sin(phi2)
    t11 = -R2*t10 + r*t10 + y
    t12 = ca.cos(phi2)
    t13 = -R2*t12 + r*t12 + x
    t14 = t10*t11 + t12*t13
    t15 = (1/2)*(L2**2 - l2**2 + t11**2 + t13**2 + t8**2)/(L2*ca.sqrt(t14**2 + t9**2))
    t16 = z - z3
    t17 = -t16
    t18 = ca.sin(phi3)
    t19 = -R3*t18 + r*t18 + y
    t20 = ca.cos(phi3)
    t21 = -R3*t20 + r*t20 + x
    t22 = t18*t19 + t20*t21
    t23 = (1/2)*(L3**2 - l3**2 + t16**2 + t19**2 + t21**2)/(L3*ca.sqrt(t17**2 + t22**2))
    theta = ca.vertcat(-ca.acos(t7) + ca.atan2(t1, t6), -ca.acos(t15) + ca.atan2(t9, t14), -ca.acos(t23) + ca.atan2(t17, t22))
    ratio = ca.vertcat(t7, t15, t23)
    return (theta, ratio,)


def _fk(theta, g):
    """Forward kinematics on the chosen assembly mode."""
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    l1 = g[12]
    l2 = g[13]
    l3 = g[14]
    r = g[15]
    t0 = L1*ca.sin(theta1)
    t1 = t0 - z1
    t2 = -L2*ca.sin(theta2) + t1 + z2
    t3 = ca.sin(phi2)
    t4 = ca.cos(theta2)
    t5 = ca.sin(phi1)
    t6 = L1*ca.cos(theta1)
    t7 = R1*t5 - r*t5 + t5*t6
    t8 = L2*t3*t4 + R2*t3 - r*t3 - t7
    t9 = ca.cos(phi2)
    t10 = ca.cos(phi1)
    t11 = R1*t10 - r*t10 + t10*t6
    t12 = L2*t4*t9 + R2*t9 - r*t9 - t11
    t13 = t12**2 + t2**2 + t8**2
    t14 = 1/ca.sqrt(t13)
    t15 = L3*ca.sin(theta3)
    t16 = t1 - t15 + z3
    t17 = t14*t2
    t18 = ca.sin(phi3)
    t19 = ca.cos(theta3)
    t20 = -L3*t18*t19 - R3*t18 + r*t18 + t7
    t21 = -t20
    t22 = t14*t8
    t23 = ca.cos(phi3)
    t24 = -L3*t19*t23 - R3*t23 + r*t23 + t11
    t25 = -t24
    t26 = t12*t14
    t27 = t16*t17 + t21*t22 + t25*t26
    t28 = -t0 + z1
    t29 = -t15 - t17*t27 - t28 + z3
    t30 = -t20 - t22*t27
    t31 = -t24 - t26*t27
    t32 = 1/ca.sqrt(t29**2 + t30**2 + t31**2)
    t33 = t29*t32
    t34 = t16*t33
    t35 = t30*t32
    t36 = t21*t35
    t37 = t31*t32
    t38 = t25*t37
    t39 = t34 + t36 + t38
    t40 = l1**2
    t41 = -l2**2 + t13 + t40
    t42 = (1/2)*t41
    t43 = -t14*t27*t42/t39 + (-l3**2 + t27**2 + t39**2 + t40)/(2*t34 + 2*t36 + 2*t38)
    t44 = 1/t13
    t45 = t42*t44
    t46 = t12*t14*t30*t32 - t22*t37
    t47 = ca.sqrt(t40 - 1/4*t41**2*t44 - t43**2)*ca.sign(t46)
    P = ca.vertcat(t11 + t12*t45 + t37*t43 - t47*(t14*t29*t32*t8 - t17*t35), t35*t43 + t45*t8 - t47*(t17*t37 - t26*t33) + t7, t2*t45 + t28 + t33*t43 - t46*t47)
    return (P,)


def _transmission(P, theta, g):
    """Singularity indicators: |s| >= margin away from a singular configuration."""
    x = P[0]
    y = P[1]
    z = P[2]
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    l1 = g[12]
    l2 = g[13]
    l3 = g[14]
    r = g[15]
    t0 = ca.cos(theta1)
    t1 = 1/l1
    t2 = ca.sin(theta1)
    t3 = L1*t2
    t4 = ca.sin(phi1)
    t5 = -y
    t6 = R1*t4
    t7 = L1*t0
    t8 = t4*t7
    t9 = t1*t2
    t10 = ca.cos(phi1)
    t11 = -x
    t12 = R1*t10
    t13 = t10*t7
    t14 = ca.cos(theta2)
    t15 = 1/l2
    t16 = ca.sin(theta2)
    t17 = L2*t16
    t18 = ca.sin(phi2)
    t19 = R2*t18
    t20 = L2*t14
    t21 = t18*t20
    t22 = t15*t16
    t23 = ca.cos(phi2)
    t24 = R2*t23
    t25 = t20*t23
    t26 = ca.cos(theta3)
    t27 = 1/l3
    t28 = ca.sin(theta3)
    t29 = L3*t28
    t30 = ca.sin(phi3)
    t31 = R3*t30
    t32 = L3*t26
    t33 = t30*t32
    t34 = t27*t28
    t35 = ca.cos(phi3)
    t36 = R3*t35
    t37 = t32*t35
    t38 = x*z2
    t39 = y*z3
    t40 = x*z3
    t41 = y*z1
    t42 = x*z1
    t43 = y*z2
    t44 = r*t18
    t45 = r*t30
    t46 = r*t4
    t47 = r*t35
    t48 = r*t10
    t49 = r*t23
    t50 = t3*x
    t51 = t3*y
    t52 = t17*y
    t53 = t17*x
    t54 = t29*x
    t55 = t29*y
    t56 = t12*t19
    t57 = t24*t6
    t58 = t36*z
    t59 = t12*t31
    t60 = R1*z
    t61 = t46*t60
    t62 = t30*t48
    t63 = t46*z2
    t64 = t35*t63
    t65 = t48*z3
    t66 = t18*t65
    t67 = t24*z
    t68 = t36*z1
    t69 = R2*z
    t70 = t35*t44
    t71 = t49*z1
    t72 = t30*t71
    t73 = t48*z
    t74 = r**2
    t75 = t74*z
    t76 = t35*t75
    t77 = t10*t75
    t78 = t23*t75
    t79 = t74*z1
    t80 = t18*t35
    t81 = t74*z2
    t82 = t10*t30
    t83 = t74*z3
    t84 = t23*t4
    t85 = t36*t6
    t86 = t18*t48
    t87 = R1*t62
    t88 = t46*z3
    t89 = R1*t23
    t90 = t24*t31
    t91 = t30*t49
    t92 = R2*t70
    t93 = t31*z
    t94 = t31*z2
    t95 = t23*t30
    t96 = t35*t4
    t97 = t10*t18
    t98 = t13*t19
    t99 = t8*z3
    t100 = t3*t36
    t101 = t7*z
    t102 = t101*t46
    t103 = t12*t21
    t104 = t25*t6
    t105 = t17*t48
    t106 = t46*z
    t107 = t20*z
    t108 = t29*t46
    t109 = t37*z
    t110 = t12*t33
    t111 = t37*z1
    t112 = t3*t74
    t113 = t17*t74
    t114 = t29*t74
    t115 = t3*t91
    t116 = t3*t31
    t117 = t36*t8
    t118 = t62*t7
    t119 = t23*t7
    t120 = t17*t46
    t121 = t120*t35
    t122 = t25*z1
    t123 = t20*t70
    t124 = t29*t86
    t125 = t37*t6
    t126 = t29*t48
    t127 = t24*t33
    t128 = t33*z
    t129 = t33*z2
    t130 = t13*t21
    t131 = t3*t37
    t132 = t13*t17
    t133 = t25*t8
    t134 = t3*t33
    t135 = t37*t8
    s = ca.vertcat(-t0*t1*(t3 + z - z1) - t10*t9*(r*t10 - t11 - t12 - t13) - t4*t9*(r*t4 - t5 - t6 - t8), -t14*t15*(t17 + z - z2) - t18*t22*(r*t18 - t19 - t21 - t5) - t22*t23*(r*t23 - t11 - t24 - t25), -t26*t27*(t29 + z - z3) - t30*t34*(r*t30 - t31 - t33 - t5) - t34*t35*(r*t35 - t11 - t36 - t37), t1*t15*t27*(-R1*t121 - R1*t124 + R1*t64 + R1*t66 - R2*t115 + R2*t72 - t100*t19 - t100*t21 + t100*t44 + t101*t62 + t102*t23 - t102*t35 + t103*t29 + t103*z - t103*z3 - t104*t29 - t104*z + t104*z3 + t105*t31 + t105*t33 + t106*t25 - t106*t37 + t107*t70 - t107*t91 + t108*t119 + t108*t24 + t108*t25 + t108*t89 - t109*t19 - t109*t21 + t109*t44 + t109*t6 + t109*t8 - t110*t17 - t110*z + t110*z2 + t111*t19 + t111*t21 - t111*t44 - t112*t80 + t112*t95 - t113*t82 + t113*t96 - t114*t84 + t114*t97 - t115*t20 + t116*t25 - t116*t49 + t117*t17 - t117*z2 + t118*t17 - t118*z2 - t119*t88 + t12*t39 - t12*t43 + t12*t52 - t12*t55 - t120*t36 - t120*t37 - t121*t7 - t122*t31 - t122*t33 + t123*t3 - t123*z1 - t124*t7 + t125*t17 - t125*z2 - t126*t19 - t126*t21 + t127*t3 - t127*z1 - t128*t13 + t128*t25 - t128*t49 + t129*t13 - t129*t48 + t13*t39 - t13*t43 + t13*t52 - t13*t55 - t13*t93 + t13*t94 + t130*t29 + t130*z - t130*z3 - t131*t19 - t131*t21 + t131*t44 - t132*t31 - t132*t33 - t133*t29 - t133*z + t134*t25 - t134*t49 + t135*t17 - t135*z2 - t17*t59 + t17*t85 + t17*t87 - t18*t7*t73 - t18*t76 + t18*t77 + t19*t40 - t19*t42 + t19*t50 - t19*t54 - t19*t58 + t19*t65 + t19*t68 - t19*t73 + t20*t72 + t21*t40 - t21*t42 + t21*t50 - t21*t54 - t21*t58 + t21*t65 + t21*t68 - t21*t73 + t23*t61 - t24*t29*t8 - t24*t39 + t24*t41 - t24*t51 + t24*t55 - t24*t88 + t24*t99 - t25*t39 + t25*t41 - t25*t51 + t25*t55 - t25*t88 + t25*t93 + t25*t99 + t29*t56 - t29*t57 + t29*t98 + t3*t90 + t3*t92 - t30*t77 + t30*t78 - t31*t38 + t31*t42 - t31*t50 + t31*t53 + t31*t67 + t31*t71 + t31*t73 - t33*t38 + t33*t42 - t33*t50 + t33*t53 + t33*t67 + t33*t71 + t33*t73 - t35*t61 - t36*t41 + t36*t43 + t36*t51 - t36*t52 + t36*t63 - t37*t41 + t37*t43 + t37*t51 - t37*t52 + t37*t63 + t38*t45 - t38*t46 + t38*t6 + t38*t8 - t39*t48 + t39*t49 + t4*t76 - t4*t78 - t40*t44 + t40*t46 - t40*t6 - t40*t8 + t41*t47 - t41*t49 + t42*t44 - t42*t45 - t43*t47 + t43*t48 - t44*t50 + t44*t54 + t44*t58 - t44*t68 + t45*t50 - t45*t53 + t46*t53 - t46*t54 - t46*t58 + t46*t67 - t47*t51 + t47*t52 - t48*t52 + t48*t55 - t48*t94 + t49*t51 - t49*t55 - t49*t93 - t53*t6 - t53*t8 + t54*t6 + t54*t8 + t56*z - t56*z3 - t57*z + t57*z3 + t58*t6 + t58*t8 - t59*z + t59*z2 + t60*t62 - t60*t86 + t64*t7 + t66*t7 - t67*t8 + t69*t70 - t69*t91 + t79*t80 - t79*t95 + t81*t82 - t81*t96 + t83*t84 - t83*t97 - t85*z2 - t87*z2 - t88*t89 - t90*z1 - t92*z1 + t98*z - t98*z3))
    return (s,)


def _pose_error_jacobian(P, theta, g):
    """dP/d(robot source errors theta1 theta2 theta3 R1 R2 R3 phi1 phi2 phi3 z1 z2 z3 L1 L2 L3 l1 l2 l3), per rad or mm (implicit differentiation)."""
    x = P[0]
    y = P[1]
    z = P[2]
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    l1 = g[12]
    l2 = g[13]
    l3 = g[14]
    r = g[15]
    t0 = 2*z
    t1 = ca.cos(theta1)
    t2 = L1*t1
    t3 = 2*z1
    t4 = ca.cos(phi1)
    t5 = 2*x
    t6 = t4*t5
    t7 = ca.sin(theta1)
    t8 = L1*t7
    t9 = ca.sin(phi1)
    t10 = 2*y
    t11 = t10*t9
    t12 = 2*L1**2*t1*t7
    t13 = t9**2
    t14 = 2*R1
    t15 = t13*t14
    t16 = t4**2
    t17 = t14*t16
    t18 = 2*r
    t19 = t13*t18
    t20 = t16*t18
    t21 = t0*t2 + t11*t8 - t12*t13 - t12*t16 + t12 - t15*t8 - t17*t8 + t19*t8 - t2*t3 + t20*t8 + t6*t8
    t22 = R1*t9
    t23 = 8*x
    t24 = t23*z2
    t25 = t23*z3
    t26 = R1*t4
    t27 = 8*y
    t28 = t27*z2
    t29 = t27*z3
    t30 = ca.sin(phi2)
    t31 = R2*t30
    t32 = t23*z1
    t33 = ca.cos(phi2)
    t34 = R2*t33
    t35 = t27*z1
    t36 = ca.sin(phi3)
    t37 = R3*t36
    t38 = ca.cos(phi3)
    t39 = R3*t38
    t40 = r*t30
    t41 = r*t36
    t42 = r*t9
    t43 = r*t33
    t44 = r*t38
    t45 = r*t4
    t46 = t23*t8
    t47 = t27*t8
    t48 = t2*t9
    t49 = t2*t4
    t50 = ca.sin(theta2)
    t51 = L2*t50
    t52 = t23*t51
    t53 = t27*t51
    t54 = ca.cos(theta2)
    t55 = L2*t54
    t56 = t30*t55
    t57 = t33*t55
    t58 = ca.sin(theta3)
    t59 = L3*t58
    t60 = t23*t59
    t61 = t27*t59
    t62 = ca.cos(theta3)
    t63 = L3*t62
    t64 = t36*t63
    t65 = t38*t63
    t66 = 8*z
    t67 = t22*t66
    t68 = t26*t66
    t69 = 8*t22
    t70 = t69*z3
    t71 = 8*t26
    t72 = t71*z3
    t73 = t69*z2
    t74 = t71*z2
    t75 = t31*t66
    t76 = t34*t37
    t77 = 8*z1
    t78 = t31*t77
    t79 = t34*t66
    t80 = t34*t41
    t81 = 8*z3
    t82 = t42*t81
    t83 = t31*t81
    t84 = t39*t66
    t85 = t37*t66
    t86 = t40*t77
    t87 = t37*t43
    t88 = 8*z2
    t89 = t39*t88
    t90 = t37*t88
    t91 = r**2
    t92 = 8*t91
    t93 = t92*z
    t94 = t33*t93
    t95 = t38*t9
    t96 = t30*t4
    t97 = t30*t38
    t98 = t36*t4
    t99 = t92*z1
    t100 = t33*t36
    t101 = t92*z2
    t102 = t92*z3
    t103 = t33*t9
    t104 = 8*t8
    t105 = t104*t31
    t106 = t34*t48
    t107 = t104*t39
    t108 = t42*t66
    t109 = t108*t2
    t110 = t40*t66
    t111 = t41*t66
    t112 = t42*t88
    t113 = t2*t38
    t114 = t41*t88
    t115 = t2*t33
    t116 = t40*t81
    t117 = t51*t69
    t118 = t51*t71
    t119 = 8*t51
    t120 = t119*t42
    t121 = t119*t37
    t122 = t57*t77
    t123 = t4*t55
    t124 = t38*t55
    t125 = t59*t69
    t126 = t59*t71
    t127 = 8*t59
    t128 = t127*t42
    t129 = t127*t31
    t130 = t34*t64
    t131 = t111*t63
    t132 = t63*t77
    t133 = t33*t41
    t134 = t4*t63
    t135 = t8*t92
    t136 = t51*t92
    t137 = t59*t92
    t138 = t104*t57
    t139 = t104*t40
    t140 = t119*t41
    t141 = t2*t55
    t142 = t141*t66
    t143 = t141*t81
    t144 = t127*t40
    t145 = t104*t63
    t146 = t2*t63
    t147 = t146*t66
    t148 = t146*t88
    t149 = t55*t97
    t150 = t63*t66
    t151 = t100*t55
    t152 = t119*t146
    t153 = t127*t141
    t154 = 1/(t100*t135 - t100*t99 - t101*t95 + t101*t98 + t102*t103 - t102*t96 - t103*t137 - t103*t142 + t103*t143 - t103*t153 + t104*t130 + t104*t76 - t104*t80 - t104*t87 - t105*t39 + t105*t44 - t105*t65 - t106*t127 + t106*t81 + t107*t40 - t107*t56 + t108*t57 - t108*t65 + t109*t33 - t109*t38 - t110*t123 + t110*t124 - t110*t49 + t110*t65 + t111*t49 - t111*t57 + t112*t113 + t112*t65 - t113*t120 - t114*t134 - t114*t49 + t115*t128 - t115*t82 + t116*t123 + t116*t49 + t117*t39 - t117*t44 + t117*t65 - t118*t37 + t118*t41 - t118*t64 + t119*t39*t48 - t120*t39 - t120*t65 + t121*t45 - t121*t49 - t122*t37 + t122*t41 - t123*t144 + t124*t139 - t124*t86 - t125*t34 + t125*t43 - t125*t57 + t126*t31 - t126*t40 + t126*t56 + t128*t34 + t128*t57 - t129*t45 + t129*t49 - t130*t77 - t131*t33 + t131*t4 + t132*t133 + t132*t149 - t132*t151 - t133*t145 + t134*t140 - t135*t97 + t136*t95 - t136*t98 + t137*t96 + t138*t37 - t138*t41 + t139*t65 + t140*t49 + t142*t96 - t143*t96 - t144*t49 - t145*t149 + t145*t151 + t147*t95 - t147*t98 - t148*t95 + t148*t98 - t149*t150 + t150*t151 + t152*t95 - t152*t98 + t153*t96 + t22*t24 - t22*t25 - t22*t52 + t22*t60 - t24*t37 + t24*t41 - t24*t42 + t24*t48 - t24*t64 + t25*t31 - t25*t40 + t25*t42 - t25*t48 + t25*t56 - t26*t28 + t26*t29 + t26*t53 - t26*t61 + t28*t39 - t28*t44 + t28*t45 - t28*t49 + t28*t65 - t29*t34 + t29*t43 - t29*t45 + t29*t49 - t29*t57 - t31*t32 + t31*t46 - t31*t60 + t31*t68 - t31*t72 + t32*t37 + t32*t40 - t32*t41 - t32*t56 + t32*t64 + t34*t35 - t34*t47 + t34*t61 - t34*t67 + t34*t70 - t34*t82 - t35*t39 - t35*t43 + t35*t44 + t35*t57 - t35*t65 + t36*t94 - t37*t46 + t37*t52 - t37*t68 + t37*t74 + t39*t47 - t39*t53 + t39*t56*t77 + t39*t67 - t39*t73 - t39*t75 + t39*t78 - t39*t86 - t40*t46 + t40*t60 - t40*t68 + t40*t72 + t40*t84 + t41*t46 - t41*t52 + t41*t68 - t41*t74 - t41*t79 + t42*t52 - t42*t60 + t42*t79 - t42*t84 + t42*t89 + t43*t47 - t43*t61 + t43*t67 - t43*t70 - t43*t85 - t44*t47 + t44*t53 - t44*t67 + t44*t73 + t44*t75 - t44*t78 - t45*t53 + t45*t61 - t45*t75 + t45*t83 + t45*t85 - t45*t90 + t46*t56 - t46*t64 - t47*t57 + t47*t65 - t48*t52 + t48*t60 - t48*t79 + t48*t84 - t48*t89 + t49*t53 - t49*t61 + t49*t75 - t49*t83 - t49*t85 + t49*t90 + t52*t64 - t53*t65 - t56*t60 + t56*t68 - t56*t72 - t56*t84 + t57*t61 - t57*t67 + t57*t70 - t57*t82 + t57*t85 - t64*t68 + t64*t74 + t64*t79 + t65*t67 - t65*t73 - t65*t75 + t65*t78 - t65*t86 + t66*t76 - t76*t77 + t77*t80 + t77*t87 - t9*t94 + t93*t95 + t93*t96 - t93*t97 - t93*t98 + t97*t99)
    t155 = 4*y
    t156 = t155*z2
    t157 = 4*z
    t158 = r*t157
    t159 = t158*t30
    t160 = t155*t51
    t161 = t157*t31
    t162 = 4*z2
    t163 = 4*z3
    t164 = 4*t51
    t165 = t157*t56
    t166 = 4*t59
    t167 = -t155*t59 + t155*z3 - t157*t37 - t157*t64 + t158*t36
    t168 = t154*(4*L2*L3*t36*t50*t62 + 4*L2*R3*t36*t50 + 4*L2*t30*t54*z3 + 4*L3*r*t30*t58 + 4*R2*t30*z3 + 4*r*t36*z2 + t156 + t159 - t160 - t161 - t162*t37 - t162*t64 - t163*t40 - t164*t41 - t165 - t166*t31 - t166*t56 - t167)
    t169 = 2*z2
    t170 = t33*t5
    t171 = t10*t30
    t172 = 2*L2**2*t50*t54
    t173 = t30**2
    t174 = 2*R2
    t175 = t173*t174
    t176 = t33**2
    t177 = t174*t176
    t178 = t173*t18
    t179 = t176*t18
    t180 = t0*t55 - t169*t55 + t170*t51 + t171*t51 - t172*t173 - t172*t176 + t172 - t175*t51 - t177*t51 + t178*t51 + t179*t51
    t181 = 4*z1
    t182 = 4*t8
    t183 = t155*t8 - t155*z1 + t157*t22 + t157*t48 - t158*t9
    t184 = t154*(-t163*t22 + t163*t42 - t163*t48 + t166*t22 - t166*t42 + t166*t48 + t167 + t181*t37 - t181*t41 + t181*t64 - t182*t37 + t182*t41 - t182*t64 + t183)
    t185 = 2*z3
    t186 = t38*t5
    t187 = t10*t36
    t188 = 2*L3**2*t58*t62
    t189 = t36**2
    t190 = 2*R3
    t191 = t189*t190
    t192 = t38**2
    t193 = t190*t192
    t194 = t18*t189
    t195 = t18*t192
    t196 = t0*t63 - t185*t63 + t186*t59 + t187*t59 - t188*t189 - t188*t192 + t188 - t191*t59 - t193*t59 + t194*t59 + t195*t59
    t197 = t154*(4*L1*L2*t30*t54*t7 + 4*L1*R2*t30*t7 + 4*L1*t1*t9*z2 + 4*L2*r*t50*t9 + 4*R1*t9*z2 + 4*r*t30*z1 - t156 - t159 + t160 + t161 - t162*t42 - t164*t22 - t164*t48 + t165 - t181*t31 - t181*t56 - t182*t40 - t183)
    t198 = 2*L1
    t199 = t1*t198
    t200 = -t11 + t13*t199 + t15 + t16*t199 + t17 - t19 - t20 - t6
    t201 = 2*L2
    t202 = t201*t54
    t203 = -t170 - t171 + t173*t202 + t175 + t176*t202 + t177 - t178 - t179
    t204 = 2*L3
    t205 = t204*t62
    t206 = -t186 - t187 + t189*t205 + t191 + t192*t205 + t193 - t194 - t195
    t207 = t18*x
    t208 = t18*y
    t209 = -t10*t26 - t10*t49 - t207*t9 + t208*t4 + t22*t5 + t48*t5
    t210 = -t10*t34 - t10*t57 - t207*t30 + t208*t33 + t31*t5 + t5*t56
    t211 = -t10*t39 - t10*t65 - t207*t36 + t208*t38 + t37*t5 + t5*t64
    t212 = -t0 - t198*t7 + 2*z1
    t213 = -t0 - t201*t50 + 2*z2
    t214 = -t0 - t204*t58 + 2*z3
    t215 = t1**2*t198
    t216 = t0*t7 - t1*t11 + t1*t15 + t1*t17 - t1*t19 - t1*t20 - t1*t6 + t13*t215 + t16*t215 + t198*t7**2 - t3*t7
    t217 = t201*t54**2
    t218 = t0*t50 - t169*t50 - t170*t54 - t171*t54 + t173*t217 + t175*t54 + t176*t217 + t177*t54 - t178*t54 - t179*t54 + t201*t50**2
    t219 = t204*t62**2
    t220 = t0*t58 - t185*t58 - t186*t62 - t187*t62 + t189*t219 + t191*t62 + t192*t219 + t193*t62 - t194*t62 - t195*t62 + t204*t58**2
    t221 = 2*l1
    t222 = 2*l2
    t223 = 2*l3
    t224 = 4*x
    t225 = t224*z2
    t226 = t224*t51
    t227 = t157*t34
    t228 = t158*t33
    t229 = t157*t57
    t230 = t157*t39 + t157*t65 - t158*t38 + t224*t59 - t224*z3
    t231 = t154*(4*L2*L3*t33*t54*t58 + 4*L2*r*t38*t50 + 4*L3*R2*t33*t58 + 4*L3*t38*t62*z2 + 4*R3*t38*z2 + 4*r*t33*z3 - t162*t44 - t163*t34 - t163*t57 - t164*t39 - t164*t65 - t166*t43 - t225 + t226 + t227 - t228 + t229 - t230)
    t232 = -t157*t26 - t157*t49 + t158*t4 - t224*t8 + t224*z1
    t233 = t154*(-r*t163*t4 + t163*t26 + t163*t49 - t166*t26 + t166*t45 - t166*t49 - t181*t39 + t181*t44 - t181*t65 + t182*t39 - t182*t44 + t182*t65 + t230 + t232)
    t234 = t154*(4*L1*L2*t1*t4*t50 + 4*L1*r*t33*t7 + 4*L2*R1*t4*t50 + 4*L2*t33*t54*z1 + 4*R2*t33*z1 + 4*r*t4*z2 - t162*t26 - t162*t49 - t164*t45 - t181*t43 - t182*t34 - t182*t57 + t225 - t226 - t227 + t228 - t229 - t232)
    t235 = t224*t31
    t236 = t155*t43
    t237 = t155*t34
    t238 = t224*t40
    t239 = 4*t91
    t240 = t224*t56
    t241 = t155*t57
    t242 = 4*t31
    t243 = 4*t34
    t244 = 4*t37
    t245 = 4*t39
    t246 = 4*t41
    t247 = t246*t63
    t248 = 4*t63
    t249 = -t155*t39 + t155*t44 - t155*t65 + t224*t37 - t224*t41 + t224*t64
    t250 = t154*(4*L2*L3*t33*t36*t54*t62 + 4*L2*R3*t33*t36*t54 + 4*L2*r*t30*t38*t54 + 4*L3*R2*t33*t36*t62 + 4*L3*r*t30*t38*t62 + 4*R2*R3*t33*t36 + 4*R2*r*t30*t38 + 4*R3*r*t30*t38 - t149*t248 + t235 + t236 - t237 - t238 - t239*t97 + t240 - t241 - t242*t39 - t242*t65 - t243*t41 - t244*t43 - t245*t56 - t246*t57 - t247*t33 - t249 + 4*t33*t36*t91)
    t251 = t239*t9
    t252 = 4*t22
    t253 = 4*t26
    t254 = 4*t42
    t255 = t2*t248
    t256 = t155*t26 - t155*t45 + t155*t49 - t22*t224 + t224*t42 - t224*t48
    t257 = t154*(-t2*t254*t38 + t22*t245 - t239*t36*t4 - t244*t26 + t244*t45 - t244*t49 - t245*t42 + t245*t48 + t246*t49 + t247*t4 + t249 + t251*t38 - t252*t44 + t252*t65 + t253*t41 - t253*t64 - t254*t65 + t255*t95 - t255*t98 + t256)
    t258 = 4*t40
    t259 = t154*(4*L1*L2*t1*t30*t4*t54 + 4*L1*R2*t1*t30*t4 + 4*L1*r*t1*t33*t9 + 4*L2*R1*t30*t4*t54 + 4*L2*r*t33*t54*t9 + 4*R1*R2*t30*t4 + 4*R1*r*t33*t9 + 4*R2*r*t33*t9 - 4*t103*t141 - t123*t258 - t22*t243 - t235 - t236 + t237 + t238 - t240 + t241 - t242*t45 - t243*t48 - t251*t33 - t252*t57 - t253*t40 - t256 - t258*t49 + 4*t30*t4*t91)
    J_src = ca.vertcat(
        ca.horzcat(-t168*t21, -t180*t184, -t196*t197, -t168*t200, -t184*t203, -t197*t206, -t168*t209, -t184*t210, -t197*t211, -t168*t212, -t184*t213, -t197*t214, -t168*t216, -t184*t218, -t197*t220, t168*t221, t184*t222, t197*t223),
        ca.horzcat(-t21*t231, -t180*t233, -t196*t234, -t200*t231, -t203*t233, -t206*t234, -t209*t231, -t210*t233, -t211*t234, -t212*t231, -t213*t233, -t214*t234, -t216*t231, -t218*t233, -t220*t234, t221*t231, t222*t233, t223*t234),
        ca.horzcat(-t21*t250, -t180*t257, -t196*t259, -t200*t250, -t203*t257, -t206*t259, -t209*t250, -t210*t257, -t211*t259, -t212*t250, -t213*t257, -t214*t259, -t216*t250, -t218*t257, -t220*t259, t221*t250, t222*t257, t223*t259),
    )
    return (J_src,)


def _error_jacobian(P, theta, g):
    """dP/d(offsets as lengths: lever_i dtheta_i for a revolute joint, ds_i for a prismatic one) (paper Eq. 13 in n dimensions)."""
    x = P[0]
    y = P[1]
    z = P[2]
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    r = g[15]
    t0 = 4*y
    t1 = t0*z2
    t2 = ca.sin(phi2)
    t3 = 4*z
    t4 = r*t3
    t5 = t2*t4
    t6 = ca.sin(phi3)
    t7 = ca.sin(theta2)
    t8 = L2*t7
    t9 = t0*t8
    t10 = R2*t2
    t11 = t10*t3
    t12 = R3*t6
    t13 = 4*z2
    t14 = 4*z3
    t15 = r*t2
    t16 = ca.cos(theta2)
    t17 = ca.sin(theta3)
    t18 = r*t6
    t19 = 4*t8
    t20 = L2*t16
    t21 = t2*t20
    t22 = t21*t3
    t23 = L3*t17
    t24 = 4*t23
    t25 = ca.cos(theta3)
    t26 = L3*t25
    t27 = t26*t6
    t28 = -t0*t23 + t0*z3 - t12*t3 - t27*t3 + t4*t6
    t29 = ca.sin(phi1)
    t30 = R1*t29
    t31 = 8*x
    t32 = t31*z2
    t33 = t31*z3
    t34 = ca.cos(phi1)
    t35 = R1*t34
    t36 = 8*y
    t37 = t36*z2
    t38 = t36*z3
    t39 = t31*z1
    t40 = ca.cos(phi2)
    t41 = R2*t40
    t42 = t36*z1
    t43 = ca.cos(phi3)
    t44 = R3*t43
    t45 = r*t29
    t46 = r*t40
    t47 = r*t43
    t48 = r*t34
    t49 = ca.sin(theta1)
    t50 = L1*t49
    t51 = t31*t50
    t52 = t36*t50
    t53 = ca.cos(theta1)
    t54 = L1*t53
    t55 = t29*t54
    t56 = t34*t54
    t57 = t31*t8
    t58 = t36*t8
    t59 = t20*t40
    t60 = t23*t31
    t61 = t23*t36
    t62 = t26*t43
    t63 = 8*z
    t64 = t30*t63
    t65 = t35*t63
    t66 = 8*t30
    t67 = t66*z3
    t68 = 8*t35
    t69 = t68*z3
    t70 = t66*z2
    t71 = t68*z2
    t72 = t10*t63
    t73 = t12*t41
    t74 = 8*z1
    t75 = t10*t74
    t76 = t41*t63
    t77 = t18*t41
    t78 = 8*z3
    t79 = t45*t78
    t80 = t10*t78
    t81 = t44*t63
    t82 = t12*t63
    t83 = t15*t74
    t84 = t12*t46
    t85 = 8*z2
    t86 = t44*t85
    t87 = t12*t85
    t88 = r**2
    t89 = 8*t88
    t90 = t89*z
    t91 = t40*t90
    t92 = t29*t43
    t93 = t2*t34
    t94 = t2*t43
    t95 = t34*t6
    t96 = t89*z1
    t97 = t40*t6
    t98 = t89*z2
    t99 = t89*z3
    t100 = t29*t40
    t101 = 8*t50
    t102 = t10*t101
    t103 = t41*t55
    t104 = t101*t44
    t105 = t45*t63
    t106 = t105*t54
    t107 = t15*t63
    t108 = t18*t63
    t109 = t45*t85
    t110 = t43*t54
    t111 = t18*t85
    t112 = t40*t54
    t113 = t15*t78
    t114 = t66*t8
    t115 = t68*t8
    t116 = 8*t8
    t117 = t116*t45
    t118 = t116*t12
    t119 = t59*t74
    t120 = t20*t34
    t121 = t20*t43
    t122 = t23*t66
    t123 = t23*t68
    t124 = 8*t23
    t125 = t124*t45
    t126 = t10*t124
    t127 = t27*t41
    t128 = t108*t26
    t129 = t26*t74
    t130 = t18*t40
    t131 = t26*t34
    t132 = t50*t89
    t133 = t8*t89
    t134 = t23*t89
    t135 = t101*t59
    t136 = t101*t15
    t137 = t116*t18
    t138 = t20*t54
    t139 = t138*t63
    t140 = t138*t78
    t141 = t124*t15
    t142 = t101*t26
    t143 = t26*t54
    t144 = t143*t63
    t145 = t143*t85
    t146 = t20*t94
    t147 = t26*t63
    t148 = t20*t97
    t149 = t116*t143
    t150 = t124*t138
    t151 = 1/(t10*t123 + t10*t33 - t10*t39 + t10*t51 - t10*t60 + t10*t65 - t10*t69 - t100*t134 - t100*t139 + t100*t140 - t100*t150 + t100*t99 + t101*t127 + t101*t73 - t101*t77 - t101*t84 - t102*t44 + t102*t47 - t102*t62 - t103*t124 + t103*t78 + t104*t15 - t104*t21 + t105*t59 - t105*t62 + t106*t40 - t106*t43 - t107*t120 + t107*t121 - t107*t56 + t107*t62 + t108*t56 - t108*t59 + t109*t110 + t109*t62 - t110*t117 - t111*t131 - t111*t56 + t112*t125 - t112*t79 + t113*t120 + t113*t56 + t114*t44 - t114*t47 + t114*t62 - t115*t12 + t115*t18 - t115*t27 + t116*t44*t55 - t117*t44 - t117*t62 + t118*t48 - t118*t56 - t119*t12 + t119*t18 + t12*t135 - t12*t32 + t12*t39 - t12*t51 + t12*t57 - t12*t65 + t12*t71 - t120*t141 + t121*t136 - t121*t83 - t122*t41 + t122*t46 - t122*t59 - t123*t15 + t123*t21 + t125*t41 + t125*t59 - t126*t48 + t126*t56 - t127*t74 + t128*t34 - t128*t40 + t129*t130 + t129*t146 - t129*t148 - t130*t142 + t131*t137 - t132*t94 + t132*t97 + t133*t92 - t133*t95 + t134*t93 - t135*t18 + t136*t62 + t137*t56 + t139*t93 - t140*t93 - t141*t56 - t142*t146 + t142*t148 + t144*t92 - t144*t95 - t145*t92 + t145*t95 - t146*t147 + t147*t148 + t149*t92 - t149*t95 - t15*t33 + t15*t39 - t15*t51 + t15*t60 - t15*t65 + t15*t69 + t15*t81 + t150*t93 + t18*t32 - t18*t39 + t18*t51 - t18*t57 + t18*t65 - t18*t71 - t18*t76 + t21*t33 - t21*t39 + t21*t44*t74 + t21*t51 - t21*t60 + t21*t65 - t21*t69 - t21*t81 - t27*t32 + t27*t39 - t27*t51 + t27*t57 - t27*t65 + t27*t71 + t27*t76 - t29*t91 + t30*t32 - t30*t33 - t30*t57 + t30*t60 - t32*t45 + t32*t55 + t33*t45 - t33*t55 - t35*t37 + t35*t38 + t35*t58 - t35*t61 + t37*t44 - t37*t47 + t37*t48 - t37*t56 + t37*t62 - t38*t41 + t38*t46 - t38*t48 + t38*t56 - t38*t59 + t41*t42 - t41*t52 + t41*t61 - t41*t64 + t41*t67 - t41*t79 - t42*t44 - t42*t46 + t42*t47 + t42*t59 - t42*t62 + t44*t52 - t44*t58 + t44*t64 - t44*t70 - t44*t72 + t44*t75 - t44*t83 + t45*t57 - t45*t60 + t45*t76 - t45*t81 + t45*t86 + t46*t52 - t46*t61 + t46*t64 - t46*t67 - t46*t82 - t47*t52 + t47*t58 - t47*t64 + t47*t70 + t47*t72 - t47*t75 - t48*t58 + t48*t61 - t48*t72 + t48*t80 + t48*t82 - t48*t87 - t52*t59 + t52*t62 - t55*t57 + t55*t60 - t55*t76 + t55*t81 - t55*t86 + t56*t58 - t56*t61 + t56*t72 - t56*t80 - t56*t82 + t56*t87 - t58*t62 + t59*t61 - t59*t64 + t59*t67 - t59*t79 + t59*t82 + t6*t91 + t62*t64 - t62*t70 - t62*t72 + t62*t75 - t62*t83 + t63*t73 - t73*t74 + t74*t77 + t74*t84 + t90*t92 + t90*t93 - t90*t94 - t90*t95 - t92*t98 - t93*t99 + t94*t96 + t95*t98 - t96*t97)
    t152 = 2*t53
    t153 = L1*t152
    t154 = 2*t50
    t155 = L1**2*t152*t49
    t156 = t29**2
    t157 = R1*t154
    t158 = t34**2
    t159 = r*t154
    t160 = t151*(t153*z - t153*z1 + t154*t29*y + t154*t34*x - t155*t156 - t155*t158 + t155 - t156*t157 + t156*t159 - t157*t158 + t158*t159)/L1
    t161 = 4*z1
    t162 = 4*t50
    t163 = t0*t50 - t0*z1 - t29*t4 + t3*t30 + t3*t55
    t164 = 2*t16
    t165 = L2*t164
    t166 = 2*t8
    t167 = L2**2*t164*t7
    t168 = t2**2
    t169 = R2*t166
    t170 = t40**2
    t171 = r*t166
    t172 = t151*(t165*z - t165*z2 + t166*t2*y + t166*t40*x - t167*t168 - t167*t170 + t167 - t168*t169 + t168*t171 - t169*t170 + t170*t171)/L2
    t173 = 2*t25
    t174 = L3*t173
    t175 = 2*t23
    t176 = L3**2*t17*t173
    t177 = t6**2
    t178 = R3*t175
    t179 = t43**2
    t180 = r*t175
    t181 = t151*(t174*z - t174*z3 + t175*t43*x + t175*t6*y - t176*t177 - t176*t179 + t176 - t177*t178 + t177*t180 - t178*t179 + t179*t180)/L3
    t182 = 4*x
    t183 = t182*z2
    t184 = t182*t8
    t185 = t3*t41
    t186 = t4*t40
    t187 = t3*t59
    t188 = t182*t23 - t182*z3 + t3*t44 + t3*t62 - t4*t43
    t189 = -t182*t50 + t182*z1 - t3*t35 - t3*t56 + t34*t4
    t190 = t10*t182
    t191 = t0*t46
    t192 = t0*t41
    t193 = t15*t182
    t194 = 4*t88
    t195 = t182*t21
    t196 = t0*t59
    t197 = 4*t10
    t198 = 4*t41
    t199 = 4*t12
    t200 = 4*t44
    t201 = 4*t18
    t202 = t201*t26
    t203 = 4*t26
    t204 = -t0*t44 + t0*t47 - t0*t62 + t12*t182 - t18*t182 + t182*t27
    t205 = t194*t29
    t206 = 4*t30
    t207 = 4*t35
    t208 = 4*t45
    t209 = t203*t54
    t210 = t0*t35 - t0*t48 + t0*t56 - t182*t30 + t182*t45 - t182*t55
    t211 = 4*t15
    J = ca.vertcat(
        ca.horzcat(-t160*(4*L2*L3*t25*t6*t7 + 4*L2*R3*t6*t7 + 4*L2*t16*t2*z3 + 4*L3*r*t17*t2 + 4*R2*t2*z3 + 4*r*t6*z2 + t1 - t10*t24 - t11 - t12*t13 - t13*t27 - t14*t15 - t18*t19 - t21*t24 - t22 - t28 + t5 - t9), -t172*(t12*t161 - t12*t162 - t14*t30 + t14*t45 - t14*t55 - t161*t18 + t161*t27 + t162*t18 - t162*t27 + t163 + t24*t30 - t24*t45 + t24*t55 + t28), -t181*(4*L1*L2*t16*t2*t49 + 4*L1*R2*t2*t49 + 4*L1*t29*t53*z2 + 4*L2*r*t29*t7 + 4*R1*t29*z2 + 4*r*t2*z1 - t1 - t10*t161 + t11 - t13*t45 - t15*t162 - t161*t21 - t163 - t19*t30 - t19*t55 + t22 - t5 + t9)),
        ca.horzcat(-t160*(4*L2*L3*t16*t17*t40 + 4*L2*r*t43*t7 + 4*L3*R2*t17*t40 + 4*L3*t25*t43*z2 + 4*R3*t43*z2 + 4*r*t40*z3 - t13*t47 - t14*t41 - t14*t59 - t183 + t184 + t185 - t186 + t187 - t188 - t19*t44 - t19*t62 - t24*t46), -t172*(-r*t14*t34 + t14*t35 + t14*t56 - t161*t44 + t161*t47 - t161*t62 + t162*t44 - t162*t47 + t162*t62 + t188 + t189 - t24*t35 + t24*t48 - t24*t56), -t181*(4*L1*L2*t34*t53*t7 + 4*L1*r*t40*t49 + 4*L2*R1*t34*t7 + 4*L2*t16*t40*z1 + 4*R2*t40*z1 + 4*r*t34*z2 - t13*t35 - t13*t56 - t161*t46 - t162*t41 - t162*t59 + t183 - t184 - t185 + t186 - t187 - t189 - t19*t48)),
        ca.horzcat(-t160*(4*L2*L3*t16*t25*t40*t6 + 4*L2*R3*t16*t40*t6 + 4*L2*r*t16*t2*t43 + 4*L3*R2*t25*t40*t6 + 4*L3*r*t2*t25*t43 + 4*R2*R3*t40*t6 + 4*R2*r*t2*t43 + 4*R3*r*t2*t43 - t146*t203 - t18*t198 + t190 + t191 - t192 - t193 - t194*t94 + t195 - t196 - t197*t44 - t197*t62 - t199*t46 - t200*t21 - t201*t59 - t202*t40 - t204 + 4*t40*t6*t88), -t172*(t18*t207 - t194*t34*t6 - t199*t35 + t199*t48 - t199*t56 + t200*t30 - t200*t45 + t200*t55 + t201*t56 + t202*t34 + t204 + t205*t43 - t206*t47 + t206*t62 - t207*t27 - t208*t43*t54 - t208*t62 + t209*t92 - t209*t95 + t210), -t181*(4*L1*L2*t16*t2*t34*t53 + 4*L1*R2*t2*t34*t53 + 4*L1*r*t29*t40*t53 + 4*L2*R1*t16*t2*t34 + 4*L2*r*t16*t29*t40 + 4*R1*R2*t2*t34 + 4*R1*r*t29*t40 + 4*R2*r*t29*t40 - 4*t100*t138 - t120*t211 - t15*t207 - t190 - t191 + t192 + t193 - t195 + t196 - t197*t48 - t198*t30 - t198*t55 + 4*t2*t34*t88 - t205*t40 - t206*t59 - t210 - t211*t56)),
    )
    return (J,)


def _measuring(P, g):
    """Nominal measuring-mechanism length |O2 - O1| and its unit vector."""
    x = P[0]
    y = P[1]
    z = P[2]
    cx = g[16]
    cy = g[17]
    cz = g[18]
    dx = g[19]
    dy = g[20]
    dz = g[21]
    t0 = -cx - dx + x
    t1 = -cy - dy + y
    t2 = -cz - dz + z
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
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    r = g[15]
    cx = g[16]
    cy = g[17]
    cz = g[18]
    dx = g[19]
    dy = g[20]
    dz = g[21]
    t0 = 4*y
    t1 = t0*z2
    t2 = ca.sin(phi2)
    t3 = 4*z
    t4 = r*t3
    t5 = t2*t4
    t6 = ca.sin(phi3)
    t7 = ca.sin(theta2)
    t8 = L2*t7
    t9 = t0*t8
    t10 = R2*t2
    t11 = t10*t3
    t12 = R3*t6
    t13 = 4*z2
    t14 = 4*z3
    t15 = r*t2
    t16 = ca.cos(theta2)
    t17 = ca.sin(theta3)
    t18 = r*t6
    t19 = 4*t8
    t20 = L2*t16
    t21 = t2*t20
    t22 = t21*t3
    t23 = L3*t17
    t24 = 4*t23
    t25 = ca.cos(theta3)
    t26 = L3*t25
    t27 = t26*t6
    t28 = -t0*t23 + t0*z3 - t12*t3 - t27*t3 + t4*t6
    t29 = ca.sin(phi1)
    t30 = R1*t29
    t31 = 8*x
    t32 = t31*z2
    t33 = t31*z3
    t34 = ca.cos(phi1)
    t35 = R1*t34
    t36 = 8*y
    t37 = t36*z2
    t38 = t36*z3
    t39 = t31*z1
    t40 = ca.cos(phi2)
    t41 = R2*t40
    t42 = t36*z1
    t43 = ca.cos(phi3)
    t44 = R3*t43
    t45 = r*t29
    t46 = r*t40
    t47 = r*t43
    t48 = r*t34
    t49 = ca.sin(theta1)
    t50 = L1*t49
    t51 = t31*t50
    t52 = t36*t50
    t53 = ca.cos(theta1)
    t54 = L1*t53
    t55 = t29*t54
    t56 = t34*t54
    t57 = t31*t8
    t58 = t36*t8
    t59 = t20*t40
    t60 = t23*t31
    t61 = t23*t36
    t62 = t26*t43
    t63 = 8*z
    t64 = t30*t63
    t65 = t35*t63
    t66 = 8*t30
    t67 = t66*z3
    t68 = 8*t35
    t69 = t68*z3
    t70 = t66*z2
    t71 = t68*z2
    t72 = t10*t63
    t73 = t12*t41
    t74 = 8*z1
    t75 = t10*t74
    t76 = t41*t63
    t77 = t18*t41
    t78 = 8*z3
    t79 = t41*t78
    t80 = t10*t78
    t81 = t44*t63
    t82 = t12*t63
    t83 = t15*t74
    t84 = t12*t46
    t85 = 8*z2
    t86 = t44*t85
    t87 = t12*t85
    t88 = r**2
    t89 = 8*t88
    t90 = t89*z
    t91 = t40*t90
    t92 = t29*t43
    t93 = t2*t34
    t94 = t2*t43
    t95 = t34*t6
    t96 = t89*z1
    t97 = t40*t6
    t98 = t89*z2
    t99 = t89*z3
    t100 = t29*t40
    t101 = 8*t50
    t102 = t10*t101
    t103 = t101*t44
    t104 = t46*t63
    t105 = t47*t63
    t106 = t15*t63
    t107 = t18*t63
    t108 = t47*t85
    t109 = t18*t85
    t110 = t46*t78
    t111 = t15*t78
    t112 = t66*t8
    t113 = t68*t8
    t114 = 8*t8
    t115 = t114*t44
    t116 = t114*t12
    t117 = t12*t59
    t118 = t104*t20
    t119 = t20*t34
    t120 = t20*t43
    t121 = t20*t74
    t122 = t46*t6
    t123 = t20*t29
    t124 = t23*t66
    t125 = t23*t68
    t126 = 8*t23
    t127 = t126*t41
    t128 = t10*t126
    t129 = t27*t74
    t130 = t26*t29
    t131 = t26*t34
    t132 = t50*t89
    t133 = t8*t89
    t134 = t23*t89
    t135 = t114*t47
    t136 = t101*t15
    t137 = t101*t20
    t138 = t114*t18
    t139 = t20*t54
    t140 = t139*t63
    t141 = t139*t78
    t142 = t101*t27
    t143 = t126*t46
    t144 = t126*t15
    t145 = t26*t54
    t146 = t145*t63
    t147 = t145*t85
    t148 = t26*t94
    t149 = t20*t63
    t150 = t26*t97
    t151 = t114*t145
    t152 = t126*t139
    t153 = 1/(t10*t125 + t10*t33 - t10*t39 + t10*t51 - t10*t60 + t10*t65 - t10*t69 - t100*t134 - t100*t140 + t100*t141 - t100*t152 + t100*t99 + t101*t117 + t101*t73 - t101*t77 - t101*t84 - t102*t44 + t102*t47 - t102*t62 + t103*t15 - t103*t21 - t104*t27 + t104*t55 - t105*t130 - t105*t55 - t106*t119 + t106*t120 - t106*t56 + t106*t62 + t107*t131 + t107*t56 + t108*t130 + t108*t55 - t109*t131 - t109*t56 - t110*t123 - t110*t55 + t111*t119 + t111*t56 + t112*t44 - t112*t47 + t112*t62 - t113*t12 + t113*t18 - t113*t27 - t115*t45 + t115*t55 + t116*t48 - t116*t56 - t117*t74 + t118*t29 - t118*t6 - t119*t144 - t12*t32 + t12*t39 - t12*t51 + t12*t57 - t12*t65 + t12*t71 + t120*t136 - t120*t83 + t121*t122 + t121*t148 - t121*t150 - t122*t137 + t123*t143 - t124*t41 + t124*t46 - t124*t59 - t125*t15 + t125*t21 + t127*t45 - t127*t55 - t128*t48 + t128*t56 - t129*t41 + t129*t46 - t130*t135 + t131*t138 - t132*t94 + t132*t97 + t133*t92 - t133*t95 + t134*t93 - t135*t55 + t136*t62 - t137*t148 + t137*t150 + t138*t56 + t140*t93 - t141*t93 + t142*t41 - t142*t46 + t143*t55 - t144*t56 + t146*t92 - t146*t95 - t147*t92 + t147*t95 - t148*t149 + t149*t150 - t15*t33 + t15*t39 - t15*t51 + t15*t60 - t15*t65 + t15*t69 + t15*t81 + t151*t92 - t151*t95 + t152*t93 + t18*t32 - t18*t39 + t18*t51 - t18*t57 + t18*t65 - t18*t71 - t18*t76 + t21*t33 - t21*t39 + t21*t44*t74 + t21*t51 - t21*t60 + t21*t65 - t21*t69 - t21*t81 - t27*t32 + t27*t39 - t27*t51 + t27*t57 - t27*t65 + t27*t71 + t27*t76 - t29*t91 + t30*t32 - t30*t33 - t30*t57 + t30*t60 - t32*t45 + t32*t55 + t33*t45 - t33*t55 - t35*t37 + t35*t38 + t35*t58 - t35*t61 + t37*t44 - t37*t47 + t37*t48 - t37*t56 + t37*t62 - t38*t41 + t38*t46 - t38*t48 + t38*t56 - t38*t59 + t41*t42 - t41*t52 + t41*t61 - t41*t64 + t41*t67 - t42*t44 - t42*t46 + t42*t47 + t42*t59 - t42*t62 + t44*t52 - t44*t58 + t44*t64 - t44*t70 - t44*t72 + t44*t75 - t44*t83 + t45*t57 - t45*t60 + t45*t76 - t45*t79 - t45*t81 + t45*t86 + t46*t52 - t46*t61 + t46*t64 - t46*t67 - t46*t82 - t47*t52 + t47*t58 - t47*t64 + t47*t70 + t47*t72 - t47*t75 - t48*t58 + t48*t61 - t48*t72 + t48*t80 + t48*t82 - t48*t87 - t52*t59 + t52*t62 - t55*t57 + t55*t60 - t55*t76 + t55*t79 + t55*t81 - t55*t86 + t56*t58 - t56*t61 + t56*t72 - t56*t80 - t56*t82 + t56*t87 - t58*t62 + t59*t61 - t59*t64 + t59*t67 + t59*t82 + t6*t91 + t62*t64 - t62*t70 - t62*t72 + t62*t75 - t62*t83 + t63*t73 - t73*t74 + t74*t77 + t74*t84 + t90*t92 + t90*t93 - t90*t94 - t90*t95 - t92*t98 - t93*t99 + t94*t96 + t95*t98 - t96*t97)
    t154 = -cx - dx + x
    t155 = -cy - dy + y
    t156 = -cz - dz + z
    t157 = 1/ca.sqrt(t154**2 + t155**2 + t156**2)
    t158 = t154*t157
    t159 = t153*t158
    t160 = 2*t53
    t161 = L1*t160
    t162 = 2*t50
    t163 = L1**2*t160*t49
    t164 = t29**2
    t165 = R1*t162
    t166 = t34**2
    t167 = r*t162
    t168 = (t161*z - t161*z1 + t162*t29*y + t162*t34*x - t163*t164 - t163*t166 + t163 - t164*t165 + t164*t167 - t165*t166 + t166*t167)/L1
    t169 = 4*x
    t170 = t169*z2
    t171 = t169*t8
    t172 = t3*t41
    t173 = t4*t40
    t174 = r*t13
    t175 = t3*t59
    t176 = t169*t23 - t169*z3 + t3*t44 + t3*t62 - t4*t43
    t177 = t155*t157
    t178 = t153*t168
    t179 = t10*t169
    t180 = t0*t46
    t181 = t0*t41
    t182 = t15*t169
    t183 = 4*t88
    t184 = t169*t21
    t185 = t0*t59
    t186 = 4*t10
    t187 = 4*t41
    t188 = 4*t12
    t189 = 4*t44
    t190 = 4*t46
    t191 = 4*t26
    t192 = -t0*t44 + t0*t47 - t0*t62 + t12*t169 - t169*t18 + t169*t27
    t193 = t156*t157
    t194 = 4*z1
    t195 = r*t14
    t196 = 4*t50
    t197 = t0*t50 - t0*z1 - t29*t4 + t3*t30 + t3*t55
    t198 = 2*t16
    t199 = L2*t198
    t200 = 2*t8
    t201 = L2**2*t198*t7
    t202 = t2**2
    t203 = R2*t200
    t204 = t40**2
    t205 = r*t200
    t206 = (t199*z - t199*z2 + t2*t200*y + t200*t40*x - t201*t202 - t201*t204 + t201 - t202*t203 + t202*t205 - t203*t204 + t204*t205)/L2
    t207 = -t169*t50 + t169*z1 - t3*t35 - t3*t56 + t34*t4
    t208 = t153*t206
    t209 = t183*t29
    t210 = 4*t30
    t211 = 4*t35
    t212 = 4*t47
    t213 = 4*t18
    t214 = t191*t54
    t215 = t0*t35 - t0*t48 + t0*t56 - t169*t30 + t169*t45 - t169*t55
    t216 = 2*t25
    t217 = L3*t216
    t218 = 2*t23
    t219 = L3**2*t17*t216
    t220 = t6**2
    t221 = R3*t218
    t222 = t43**2
    t223 = r*t218
    t224 = (t217*z - t217*z3 + t218*t43*x + t218*t6*y - t219*t220 - t219*t222 + t219 - t220*t221 + t220*t223 - t221*t222 + t222*t223)/L3
    t225 = t153*t224
    t226 = 4*t15
    row = ca.vertcat(
        ca.horzcat(-t159*t168*(4*L2*L3*t25*t6*t7 + 4*L2*R3*t6*t7 + 4*L2*t16*t2*z3 + 4*L3*r*t17*t2 + 4*R2*t2*z3 + 4*r*t6*z2 + t1 - t10*t24 - t11 - t12*t13 - t13*t27 - t14*t15 - t18*t19 - t21*t24 - t22 - t28 + t5 - t9) - t177*t178*(4*L2*L3*t16*t17*t40 + 4*L2*r*t43*t7 + 4*L3*R2*t17*t40 + 4*L3*t25*t43*z2 + 4*R3*t43*z2 + 4*r*t40*z3 - t14*t41 - t14*t59 - t170 + t171 + t172 - t173 - t174*t43 + t175 - t176 - t19*t44 - t19*t62 - t24*t46) - t178*t193*(4*L2*L3*t16*t25*t40*t6 + 4*L2*R3*t16*t40*t6 + 4*L2*r*t16*t2*t43 + 4*L3*R2*t25*t40*t6 + 4*L3*r*t2*t25*t43 + 4*R2*R3*t40*t6 + 4*R2*r*t2*t43 + 4*R3*r*t2*t43 + t179 - t18*t187 + t180 - t181 - t182 - t183*t94 + t184 - t185 - t186*t44 - t186*t62 - t188*t46 - t189*t21 - t190*t20*t6 - t190*t27 - t191*t20*t94 - t192 + 4*t40*t6*t88), -t159*t206*(t12*t194 - t14*t30 - t14*t55 - t18*t194 + t18*t196 - t188*t50 + t194*t27 + t195*t29 - t196*t27 + t197 + t24*t30 - t24*t45 + t24*t55 + t28) - t177*t208*(t14*t35 + t14*t56 + t176 + t189*t50 - t194*t44 + t194*t47 - t194*t62 - t195*t34 - t196*t47 + t196*t62 + t207 - t24*t35 + t24*t48 - t24*t56) - t193*t208*(-t130*t212 + t131*t213 + t18*t211 - t183*t34*t6 - t188*t35 + t188*t48 - t188*t56 + t189*t30 - t189*t45 + t189*t55 + t192 + t209*t43 - t210*t47 + t210*t62 - t211*t27 - t212*t55 + t213*t56 + t214*t92 - t214*t95 + t215), -t159*t224*(4*L1*L2*t16*t2*t49 + 4*L1*R2*t2*t49 + 4*L1*t29*t53*z2 + 4*L2*r*t29*t7 + 4*R1*t29*z2 + 4*r*t2*z1 - t1 - t10*t194 + t11 - t15*t196 - t174*t29 - t19*t30 - t19*t55 - t194*t21 - t197 + t22 - t5 + t9) - t177*t225*(4*L1*L2*t34*t53*t7 + 4*L1*r*t40*t49 + 4*L2*R1*t34*t7 + 4*L2*t16*t40*z1 + 4*R2*t40*z1 + 4*r*t34*z2 - t13*t35 - t13*t56 + t170 - t171 - t172 + t173 - t175 - t187*t50 - t19*t48 - t194*t46 - t196*t59 - t207) - t193*t225*(4*L1*L2*t16*t2*t34*t53 + 4*L1*R2*t2*t34*t53 + 4*L1*r*t29*t40*t53 + 4*L2*R1*t16*t2*t34 + 4*L2*r*t16*t29*t40 + 4*R1*R2*t2*t34 + 4*R1*r*t29*t40 + 4*R2*r*t29*t40 - 4*t100*t139 - t119*t226 - t15*t211 - t179 - t180 + t181 + t182 - t184 + t185 - t186*t48 - t187*t30 - t187*t55 + 4*t2*t34*t88 - t209*t40 - t210*t59 - t215 - t226*t56), -t158, -t177, -t193),
    )
    return (row,)


def _distance(theta_cmd, g, err):
    """Exact distance O1'O2' for commanded joints, nominal geometry and source errors."""
    theta1 = theta_cmd[0]
    theta2 = theta_cmd[1]
    theta3 = theta_cmd[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    l1 = g[12]
    l2 = g[13]
    l3 = g[14]
    r = g[15]
    cx = g[16]
    cy = g[17]
    cz = g[18]
    dx = g[19]
    dy = g[20]
    dz = g[21]
    d_theta1 = err[0]
    d_theta2 = err[1]
    d_theta3 = err[2]
    d_R1 = err[3]
    d_R2 = err[4]
    d_R3 = err[5]
    d_phi1 = err[6]
    d_phi2 = err[7]
    d_phi3 = err[8]
    d_z1 = err[9]
    d_z2 = err[10]
    d_z3 = err[11]
    d_L1 = err[12]
    d_L2 = err[13]
    d_L3 = err[14]
    d_l1 = err[15]
    d_l2 = err[16]
    d_l3 = err[17]
    d_rMx = err[18]
    d_rMy = err[19]
    d_rMz = err[20]
    t0 = L1 + d_L1
    t1 = d_theta1 + theta1
    t2 = t0*ca.sin(t1)
    t3 = L2 + d_L2
    t4 = d_theta2 + theta2
    t5 = d_z1 - t2 + z1
    t6 = d_z2 - t3*ca.sin(t4) - t5 + z2
    t7 = R2 + d_R2
    t8 = d_phi2 + phi2
    t9 = ca.sin(t8)
    t10 = t3*ca.cos(t4)
    t11 = d_phi1 + phi1
    t12 = ca.sin(t11)
    t13 = r*t12
    t14 = R1 + d_R1
    t15 = t12*t14
    t16 = t0*ca.cos(t1)
    t17 = t12*t16
    t18 = t13 - t15 - t17
    t19 = -r*t9 + t10*t9 + t18 + t7*t9
    t20 = ca.cos(t8)
    t21 = ca.cos(t11)
    t22 = r*t21
    t23 = t14*t21
    t24 = t16*t21
    t25 = t22 - t23 - t24
    t26 = -r*t20 + t10*t20 + t20*t7 + t25
    t27 = t19**2 + t26**2 + t6**2
    t28 = 1/t27
    t29 = (d_l1 + l1)**2
    t30 = t27 + t29 - (d_l2 + l2)**2
    t31 = L3 + d_L3
    t32 = d_theta3 + theta3
    t33 = -d_z3 + t31*ca.sin(t32) + t5 - z3
    t34 = -t33
    t35 = 1/ca.sqrt(t27)
    t36 = t35*t6
    t37 = R3 + d_R3
    t38 = d_phi3 + phi3
    t39 = ca.sin(t38)
    t40 = r*t39
    t41 = ca.cos(t32)
    t42 = t31*t41
    t43 = t18 + t37*t39 + t39*t42 - t40
    t44 = t19*t35
    t45 = ca.cos(t38)
    t46 = r*t45
    t47 = t25 + t37*t45 + t42*t45 - t46
    t48 = t26*t35
    t49 = t34*t36 + t43*t44 + t47*t48
    t50 = -t33 - t36*t49
    t51 = t13 - t15 - t17 + t31*t39*t41 + t37*t39 - t40 - t44*t49
    t52 = t22 - t23 - t24 + t31*t41*t45 + t37*t45 - t46 - t48*t49
    t53 = 1/ca.sqrt(t50**2 + t51**2 + t52**2)
    t54 = t50*t53
    t55 = t34*t54
    t56 = t51*t53
    t57 = t43*t56
    t58 = t52*t53
    t59 = t47*t58
    t60 = t55 + t57 + t59
    t61 = -1/2*t30*t35*t49/t60 + (t29 + t49**2 + t60**2 - (d_l3 + l3)**2)/(2*t55 + 2*t57 + 2*t59)
    t62 = t26*t35*t51*t53 - t44*t58
    t63 = ca.sqrt(-1/4*t28*t30**2 + t29 - t61**2)*ca.sign(t62)
    rho = ca.vertcat(ca.sqrt((-cx - d_rMx - dx - t25 + (1/2)*t26*t28*t30 + t52*t53*t61 - t63*(t19*t35*t50*t53 - t36*t56))**2 + (-cy - d_rMy - dy - t18 + (1/2)*t19*t28*t30 + t51*t53*t61 - t63*(t36*t58 - t48*t54))**2 + (-cz - d_rMz + d_z1 - dz - t2 + (1/2)*t28*t30*t6 + t50*t53*t61 - t62*t63 + z1)**2))
    return (rho,)


def _gauge(g):
    """Gauge motions (columns): source-error directions no distance change can see."""
    cx = g[16]
    cy = g[17]
    dx = g[19]
    dy = g[20]
    Z = ca.vertcat(
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 1),
        ca.horzcat(0, 1),
        ca.horzcat(0, 1),
        ca.horzcat(1, 0),
        ca.horzcat(1, 0),
        ca.horzcat(1, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, 0),
        ca.horzcat(0, -cy - dy),
        ca.horzcat(0, cx + dx),
        ca.horzcat(1, 0),
    )
    return (Z,)


def _sketch(P, theta, g):
    """The robot drawn as line segments (columns 2k and 2k+1: the ends of segment k), mm."""
    x = P[0]
    y = P[1]
    z = P[2]
    theta1 = theta[0]
    theta2 = theta[1]
    theta3 = theta[2]
    R1 = g[0]
    R2 = g[1]
    R3 = g[2]
    phi1 = g[3]
    phi2 = g[4]
    phi3 = g[5]
    z1 = g[6]
    z2 = g[7]
    z3 = g[8]
    L1 = g[9]
    L2 = g[10]
    L3 = g[11]
    r = g[15]
    t0 = ca.cos(phi1)
    t1 = R1*t0
    t2 = ca.cos(phi2)
    t3 = R2*t2
    t4 = ca.cos(phi3)
    t5 = R3*t4
    t6 = L1*ca.cos(theta1)
    t7 = t0*t6 + t1
    t8 = r*t0 + x
    t9 = L2*ca.cos(theta2)
    t10 = t2*t9 + t3
    t11 = r*t2 + x
    t12 = L3*ca.cos(theta3)
    t13 = t12*t4 + t5
    t14 = r*t4 + x
    t15 = ca.sin(phi1)
    t16 = R1*t15
    t17 = ca.sin(phi2)
    t18 = R2*t17
    t19 = ca.sin(phi3)
    t20 = R3*t19
    t21 = t15*t6 + t16
    t22 = r*t15 + y
    t23 = t17*t9 + t18
    t24 = r*t17 + y
    t25 = t12*t19 + t20
    t26 = r*t19 + y
    t27 = -L1*ca.sin(theta1) + z1
    t28 = -L2*ca.sin(theta2) + z2
    t29 = -L3*ca.sin(theta3) + z3
    segments = ca.vertcat(
        ca.horzcat(t1, t3, t3, t5, t5, t1, t1, t7, t7, t8, t3, t10, t10, t11, t5, t13, t13, t14, t8, t11, t11, t14, t14, t8),
        ca.horzcat(t16, t18, t18, t20, t20, t16, t16, t21, t21, t22, t18, t23, t23, t24, t20, t25, t25, t26, t22, t24, t24, t26, t26, t22),
        ca.horzcat(z1, z2, z2, z3, z3, z1, z1, t27, t27, z, z2, t28, t28, z, z3, t29, t29, z, z, z, z, z, z, z),
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
