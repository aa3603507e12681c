"""Generated CasADi builders for the mechanism ``hexapod``.

GENERATED -- DO NOT EDIT.  Regenerate with ``zerocal regen``.
source: derivations/codegen.py, derivations/geometry.py, derivations/mechanism.py, derivations/mechanisms/hexapod.py
inputs hash: 86b7b6a846bca3ea
sympy: 1.14.0
"""
import casadi as ca

NAME = 'hexapod'
#: where this module was derived from: a module name, or a .py file relative to this module
DERIVATION = 'derivations.mechanisms.hexapod'
DESCRIPTION = '6-6 Gough-Stewart hexapod (six prismatic legs) with a spherical-joint measuring mechanism'
POSE_NAMES = ['x', 'y', 'z', 'roll', 'pitch', 'yaw']
JOINT_NAMES = ['L1', 'L2', 'L3', 'L4', 'L5', 'L6']
GEOMETRY_NAMES = ['Rb', 'Rp', 'z_home', 'stroke', 'beta1', 'beta2', 'beta3', 'beta4', 'beta5', 'beta6', 'pi1', 'pi2', 'pi3', 'pi4', 'pi5', 'pi6', 'b1x', 'b1y', 'b1z', 'b2x', 'b2y', 'b2z', 'b3x', 'b3y', 'b3z', 'b4x', 'b4y', 'b4z', 'b5x', 'b5y', 'b5z', 'b6x', 'b6y', 'b6z', 'q1x', 'q1y', 'q1z', 'q2x', 'q2y', 'q2z', 'q3x', 'q3y', 'q3z', 'q4x', 'q4y', 'q4z', 'q5x', 'q5y', 'q5z', 'q6x', 'q6y', 'q6z', 'cx', 'cy', 'cz', 'dx', 'dy', 'dz']
GEOMETRY_UNITS = {'Rb': 'mm', 'Rp': 'mm', 'z_home': 'mm', 'stroke': 'mm', 'beta1': 'rad', 'beta2': 'rad', 'beta3': 'rad', 'beta4': 'rad', 'beta5': 'rad', 'beta6': 'rad', 'pi1': 'rad', 'pi2': 'rad', 'pi3': 'rad', 'pi4': 'rad', 'pi5': 'rad', 'pi6': 'rad', 'b1x': 'mm', 'b1y': 'mm', 'b1z': 'mm', 'b2x': 'mm', 'b2y': 'mm', 'b2z': 'mm', 'b3x': 'mm', 'b3y': 'mm', 'b3z': 'mm', 'b4x': 'mm', 'b4y': 'mm', 'b4z': 'mm', 'b5x': 'mm', 'b5y': 'mm', 'b5z': 'mm', 'b6x': 'mm', 'b6y': 'mm', 'b6z': 'mm', 'q1x': 'mm', 'q1y': 'mm', 'q1z': 'mm', 'q2x': 'mm', 'q2y': 'mm', 'q2z': 'mm', 'q3x': 'mm', 'q3y': 'mm', 'q3z': 'mm', 'q4x': 'mm', 'q4y': 'mm', 'q4z': 'mm', 'q5x': 'mm', 'q5y': 'mm', 'q5z': 'mm', 'q6x': 'mm', 'q6y': 'mm', 'q6z': 'mm', 'cx': 'mm', 'cy': 'mm', 'cz': 'mm', 'dx': 'mm', 'dy': 'mm', 'dz': 'mm'}
JOINT_KINDS = ['prismatic', 'prismatic', 'prismatic', 'prismatic', 'prismatic', 'prismatic']
POSE_UNITS = {'x': 'mm', 'y': 'mm', 'z': 'mm', 'roll': 'rad', 'pitch': 'rad', 'yaw': 'rad'}
#: (name, role, unit, target, lever arm) of each source error, in vector order
SOURCE_ERRORS = [
    ('L1', 'zero_offset', 'mm', 'L1', None),
    ('L2', 'zero_offset', 'mm', 'L2', None),
    ('L3', 'zero_offset', 'mm', 'L3', None),
    ('L4', 'zero_offset', 'mm', 'L4', None),
    ('L5', 'zero_offset', 'mm', 'L5', None),
    ('L6', 'zero_offset', 'mm', 'L6', None),
    ('b1x', 'geometry', 'mm', 'b1x', None),
    ('b1y', 'geometry', 'mm', 'b1y', None),
    ('b1z', 'geometry', 'mm', 'b1z', None),
    ('b2x', 'geometry', 'mm', 'b2x', None),
    ('b2y', 'geometry', 'mm', 'b2y', None),
    ('b2z', 'geometry', 'mm', 'b2z', None),
    ('b3x', 'geometry', 'mm', 'b3x', None),
    ('b3y', 'geometry', 'mm', 'b3y', None),
    ('b3z', 'geometry', 'mm', 'b3z', None),
    ('b4x', 'geometry', 'mm', 'b4x', None),
    ('b4y', 'geometry', 'mm', 'b4y', None),
    ('b4z', 'geometry', 'mm', 'b4z', None),
    ('b5x', 'geometry', 'mm', 'b5x', None),
    ('b5y', 'geometry', 'mm', 'b5y', None),
    ('b5z', 'geometry', 'mm', 'b5z', None),
    ('b6x', 'geometry', 'mm', 'b6x', None),
    ('b6y', 'geometry', 'mm', 'b6y', None),
    ('b6z', 'geometry', 'mm', 'b6z', None),
    ('q1x', 'geometry', 'mm', 'q1x', None),
    ('q1y', 'geometry', 'mm', 'q1y', None),
    ('q1z', 'geometry', 'mm', 'q1z', None),
    ('q2x', 'geometry', 'mm', 'q2x', None),
    ('q2y', 'geometry', 'mm', 'q2y', None),
    ('q2z', 'geometry', 'mm', 'q2z', None),
    ('q3x', 'geometry', 'mm', 'q3x', None),
    ('q3y', 'geometry', 'mm', 'q3y', None),
    ('q3z', 'geometry', 'mm', 'q3z', None),
    ('q4x', 'geometry', 'mm', 'q4x', None),
    ('q4y', 'geometry', 'mm', 'q4y', None),
    ('q4z', 'geometry', 'mm', 'q4z', None),
    ('q5x', 'geometry', 'mm', 'q5x', None),
    ('q5y', 'geometry', 'mm', 'q5y', None),
    ('q5z', 'geometry', 'mm', 'q5z', None),
    ('q6x', 'geometry', 'mm', 'q6x', None),
    ('q6y', 'geometry', 'mm', 'q6y', None),
    ('q6z', 'geometry', 'mm', 'q6z', None),
    ('rMx', 'measuring', 'mm', 'cx', None),
    ('rMy', 'measuring', 'mm', 'cy', None),
    ('rMz', 'measuring', 'mm', 'cz', None),
    ('ddx', 'measuring', 'mm', 'dx', None),
    ('ddy', 'measuring', 'mm', 'dy', None),
    ('ddz', 'measuring', 'mm', 'dz', None),
]
SOURCE_ERROR_NAMES = ['L1', 'L2', 'L3', 'L4', 'L5', 'L6', 'b1x', 'b1y', 'b1z', 'b2x', 'b2y', 'b2z', 'b3x', 'b3y', 'b3z', 'b4x', 'b4y', 'b4z', 'b5x', 'b5y', 'b5z', 'b6x', 'b6y', 'b6z', 'q1x', 'q1y', 'q1z', 'q2x', 'q2y', 'q2z', 'q3x', 'q3y', 'q3z', 'q4x', 'q4y', 'q4z', 'q5x', 'q5y', 'q5z', 'q6x', 'q6y', 'q6z', 'rMx', 'rMy', 'rMz', 'ddx', 'ddy', 'ddz']
HOME_JOINTS = None
#: None (HOME_JOINTS), 'workspace centre' or the name of the function giving the home pose
HOME_POSE = 'home_pose'
MEASURING_BASE = ['cx', 'cy', 'cz']
MEASURING_OFFSET = ['dx', 'dy', 'dz']
GAUGE_NAMES = ['base translation x', 'base translation y', 'base translation z', 'base rotation about x', 'base rotation about y', 'base rotation about z', 'platform translation x', 'platform translation y', 'platform translation z', 'platform rotation about x', 'platform rotation about y', 'platform rotation about z']
GAUGE_FIX = ['b1x', 'b1y', 'b1z', 'b2x', 'b2z', 'b3z', 'q1x', 'q1y', 'q1z', 'q2x', 'q2z', 'q3z']
WORKSPACE = 'box'
WORKSPACE_DEFAULTS = {}
ALIASES = {}
LIST_ALIASES = {'base_angles': ('beta1', 'beta2', 'beta3', 'beta4', 'beta5', 'beta6'), 'platform_angles': ('pi1', 'pi2', 'pi3', 'pi4', 'pi5', 'pi6')}
DEFAULTS = {'beta1': 345.0, 'beta2': 15.0, 'beta3': 105.0, 'beta4': 135.0, 'beta5': 225.0, 'beta6': 255.0, 'pi1': 315.0, 'pi2': 45.0, 'pi3': 75.0, 'pi4': 165.0, 'pi5': 195.0, 'pi6': 285.0, 'b1x': 0.0, 'b1y': 0.0, 'b1z': 0.0, 'b2x': 0.0, 'b2y': 0.0, 'b2z': 0.0, 'b3x': 0.0, 'b3y': 0.0, 'b3z': 0.0, 'b4x': 0.0, 'b4y': 0.0, 'b4z': 0.0, 'b5x': 0.0, 'b5y': 0.0, 'b5z': 0.0, 'b6x': 0.0, 'b6y': 0.0, 'b6z': 0.0, 'q1x': 0.0, 'q1y': 0.0, 'q1z': 0.0, 'q2x': 0.0, 'q2y': 0.0, 'q2z': 0.0, 'q3x': 0.0, 'q3y': 0.0, 'q3z': 0.0, 'q4x': 0.0, 'q4y': 0.0, 'q4z': 0.0, 'q5x': 0.0, 'q5y': 0.0, 'q5z': 0.0, 'q6x': 0.0, 'q6y': 0.0, 'q6z': 0.0}
PARAM_SETS = {'base': ('b1x', 'b1y', 'b1z', 'b2x', 'b2y', 'b2z', 'b3x', 'b3y', 'b3z', 'b4x', 'b4y', 'b4z', 'b5x', 'b5y', 'b5z', 'b6x', 'b6y', 'b6z'), 'platform': ('q1x', 'q1y', 'q1z', 'q2x', 'q2y', 'q2z', 'q3x', 'q3y', 'q3z', 'q4x', 'q4y', 'q4z', 'q5x', 'q5y', 'q5z', 'q6x', 'q6y', 'q6z'), 'rM': ('rMx', 'rMy', 'rMz'), 'dd': ('ddx', 'ddy', 'ddz')}
DEFAULT_SET = ('L1', 'L2', 'L3', 'L4', 'L5', 'L6', 'rMx', 'rMy', 'rMz', 'ddx', 'ddy', 'ddz')
NOISE = {'scale': 0.001, 'joint': 0.002}
POSITIVE = ['Rb', 'Rp', 'z_home', 'stroke']
FUNCTION_SIGNATURES = {
    'ik': ([('P', 6), ('g', 58)], [('theta', (6, 1)), ('ratio', (6, 1))]),
    'fk_residual': ([('P', 6), ('theta', 6), ('g', 58)], [('f', (6, 1)), ('f_P', (6, 6))]),
    'fk_start': ([('g', 58)], [('P0', (6, 1))]),
    'fk': ([('theta', 6), ('g', 58)], [('P', (6, 1))]),
    'transmission': ([('P', 6), ('theta', 6), ('g', 58)], [('s', (1, 1))]),
    'pose_error_jacobian': ([('P', 6), ('theta', 6), ('g', 58)], [('J_src', (6, 42))]),
    'error_jacobian': ([('P', 6), ('theta', 6), ('g', 58)], [('J', (6, 6))]),
    'measuring': ([('P', 6), ('g', 58)], [('lam', (1, 1)), ('lam_hat', (3, 1))]),
    'g_row': ([('P', 6), ('theta', 6), ('g', 58)], [('row', (1, 12))]),
    'distance': ([('theta_cmd', 6), ('g', 58), ('err', 48)], [('rho', (1, 1))]),
    'gauge': ([('g', 58)], [('Z', (48, 12))]),
    'home_pose': ([('g', 58)], [('P0', (6, 1))]),
    'sketch': ([('P', 6), ('theta', 6), ('g', 58)], [('segments', (3, 36))]),
}


def _ik(P, g):
    """Inverse kinematics on the chosen branch and the reach ratios (|ratio| <= 1 where reachable)."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    Rb = g[0]
    Rp = g[1]
    z_home = g[2]
    stroke = g[3]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    t0 = -b1z
    t1 = ca.cos(roll)
    t2 = ca.cos(pitch)
    t3 = t1*t2
    t4 = ca.sin(pitch)
    t5 = ca.cos(pi1)
    t6 = Rp*t5 + q1x
    t7 = ca.sin(pi1)
    t8 = Rp*t7 + q1y
    t9 = ca.sin(roll)
    t10 = t2*t9
    t11 = Rb*ca.sin(beta1)
    t12 = ca.sin(yaw)
    t13 = t2*t6
    t14 = ca.cos(yaw)
    t15 = t14*t9
    t16 = t1*t12
    t17 = -t15 + t16*t4
    t18 = t1*t14
    t19 = t12*t9
    t20 = t18 + t19*t4
    t21 = Rb*ca.cos(beta1)
    t22 = t18*t4 + t19
    t23 = t15*t4 - t16
    t24 = ca.sqrt((q1z*t3 + t0 + t10*t8 - t4*t6 + z)**2 + (-b1x + q1z*t22 + t13*t14 - t21 + t23*t8 + x)**2 + (-b1y + q1z*t17 - t11 + t12*t13 + t20*t8 + y)**2)
    t25 = -b2z
    t26 = ca.cos(pi2)
    t27 = Rp*t26 + q2x
    t28 = ca.sin(pi2)
    t29 = Rp*t28 + q2y
    t30 = Rb*ca.sin(beta2)
    t31 = t2*t27
    t32 = Rb*ca.cos(beta2)
    t33 = ca.sqrt((q2z*t3 + t10*t29 + t25 - t27*t4 + z)**2 + (-b2x + q2z*t22 + t14*t31 + t23*t29 - t32 + x)**2 + (-b2y + q2z*t17 + t12*t31 + t20*t29 - t30 + y)**2)
    t34 = -b3z
    t35 = ca.cos(pi3)
    t36 = Rp*t35 + q3x
    t37 = ca.sin(pi3)
    t38 = Rp*t37 + q3y
    t39 = Rb*ca.sin(beta3)
    t40 = t2*t36
    t41 = Rb*ca.cos(beta3)
    t42 = ca.sqrt((q3z*t3 + t10*t38 + t34 - t36*t4 + z)**2 + (-b3x + q3z*t22 + t14*t40 + t23*t38 - t41 + x)**2 + (-b3y + q3z*t17 + t12*t40 + t20*t38 - t39 + y)**2)
    t43 = -b4z
    t44 = ca.cos(pi4)
    t45 = Rp*t44 + q4x
    t46 = ca.sin(pi4)
    t47 = Rp*t46 + q4y
    t48 = Rb*ca.sin(beta4)
    t49 = t2*t45
    t50 = Rb*ca.cos(beta4)
    t51 = ca.sqrt((q4z*t3 + t10*t47 - t4*t45 + t43 + z)**2 + (-b4x + q4z*t22 + t14*t49 + t23*t47 - t50 + x)**2 + (-b4y + q4z*t17 + t12*t49 + t20*t47 - t48 + y)**2)
    t52 = -b5z
    t53 = ca.cos(pi5)
    t54 = Rp*t53 + q5x
    t55 = ca.sin(pi5)
    t56 = Rp*t55 + q5y
    t57 = Rb*ca.sin(beta5)
    t58 = t2*t54
    t59 = Rb*ca.cos(beta5)
    t60 = ca.sqrt((q5z*t3 + t10*t56 - t4*t54 + t52 + z)**2 + (-b5x + q5z*t22 + t14*t58 + t23*t56 - t59 + x)**2 + (-b5y + q5z*t17 + t12*t58 + t20*t56 - t57 + y)**2)
    t61 = -b6z
    t62 = ca.cos(pi6)
    t63 = Rp*t62 + q6x
    t64 = ca.sin(pi6)
    t65 = Rp*t64 + q6y
    t66 = Rb*ca.sin(beta6)
    t67 = t2*t63
    t68 = Rb*ca.cos(beta6)
    t69 = ca.sqrt((q6z*t3 + t10*t65 - t4*t63 + t61 + z)**2 + (-b6x + q6z*t22 + t14*t67 + t23*t65 - t68 + x)**2 + (-b6y + q6z*t17 + t12*t67 + t20*t65 - t66 + y)**2)
    t70 = 1/stroke
    theta = ca.vertcat(t24, t33, t42, t51, t60, t69)
    ratio = ca.vertcat(t70*(t24 - ca.sqrt((q1z + t0 + z_home)**2 + (Rp*t5 - b1x + q1x - t21)**2 + (Rp*t7 - b1y + q1y - t11)**2)), t70*(t33 - ca.sqrt((q2z + t25 + z_home)**2 + (Rp*t26 - b2x + q2x - t32)**2 + (Rp*t28 - b2y + q2y - t30)**2)), t70*(t42 - ca.sqrt((q3z + t34 + z_home)**2 + (Rp*t35 - b3x + q3x - t41)**2 + (Rp*t37 - b3y + q3y - t39)**2)), t70*(t51 - ca.sqrt((q4z + t43 + z_home)**2 + (Rp*t44 - b4x + q4x - t50)**2 + (Rp*t46 - b4y + q4y - t48)**2)), t70*(t60 - ca.sqrt((q5z + t52 + z_home)**2 + (Rp*t53 - b5x + q5x - t59)**2 + (Rp*t55 - b5y + q5y - t57)**2)), t70*(t69 - ca.sqrt((q6z + t61 + z_home)**2 + (Rp*t62 - b6x + q6x - t68)**2 + (Rp*t64 - b6y + q6y - t66)**2)))
    return (theta, ratio,)


def _fk_residual(P, theta, g):
    """Loop closure f(P, theta, g) and df/dP: the forward kinematics' Newton steps."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    L1 = theta[0]
    L2 = theta[1]
    L3 = theta[2]
    L4 = theta[3]
    L5 = theta[4]
    L6 = theta[5]
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    t0 = ca.cos(roll)
    t1 = ca.cos(pitch)
    t2 = t0*t1
    t3 = q1z*t2
    t4 = ca.sin(pitch)
    t5 = Rp*ca.cos(pi1) + q1x
    t6 = t4*t5
    t7 = Rp*ca.sin(pi1) + q1y
    t8 = ca.sin(roll)
    t9 = t1*t8
    t10 = t7*t9
    t11 = -b1z + t10 + t3 - t6 + z
    t12 = Rb*ca.sin(beta1)
    t13 = ca.sin(yaw)
    t14 = t1*t5
    t15 = t13*t14
    t16 = ca.cos(yaw)
    t17 = t16*t8
    t18 = t0*t13
    t19 = -t17 + t18*t4
    t20 = q1z*t19
    t21 = t0*t16
    t22 = t13*t8
    t23 = t21 + t22*t4
    t24 = t23*t7
    t25 = -b1y - t12 + t15 + t20 + t24 + y
    t26 = Rb*ca.cos(beta1)
    t27 = t14*t16
    t28 = t21*t4 + t22
    t29 = q1z*t28
    t30 = t17*t4 - t18
    t31 = t30*t7
    t32 = -b1x - t26 + t27 + t29 + t31 + x
    t33 = q2z*t2
    t34 = Rp*ca.cos(pi2) + q2x
    t35 = t34*t4
    t36 = Rp*ca.sin(pi2) + q2y
    t37 = t36*t9
    t38 = -b2z + t33 - t35 + t37 + z
    t39 = Rb*ca.sin(beta2)
    t40 = t1*t34
    t41 = t13*t40
    t42 = q2z*t19
    t43 = t23*t36
    t44 = -b2y - t39 + t41 + t42 + t43 + y
    t45 = Rb*ca.cos(beta2)
    t46 = t16*t40
    t47 = q2z*t28
    t48 = t30*t36
    t49 = -b2x - t45 + t46 + t47 + t48 + x
    t50 = q3z*t2
    t51 = Rp*ca.cos(pi3) + q3x
    t52 = t4*t51
    t53 = Rp*ca.sin(pi3) + q3y
    t54 = t53*t9
    t55 = -b3z + t50 - t52 + t54 + z
    t56 = Rb*ca.sin(beta3)
    t57 = t1*t51
    t58 = t13*t57
    t59 = q3z*t19
    t60 = t23*t53
    t61 = -b3y - t56 + t58 + t59 + t60 + y
    t62 = Rb*ca.cos(beta3)
    t63 = t16*t57
    t64 = q3z*t28
    t65 = t30*t53
    t66 = -b3x - t62 + t63 + t64 + t65 + x
    t67 = q4z*t2
    t68 = Rp*ca.cos(pi4) + q4x
    t69 = t4*t68
    t70 = Rp*ca.sin(pi4) + q4y
    t71 = t70*t9
    t72 = -b4z + t67 - t69 + t71 + z
    t73 = Rb*ca.sin(beta4)
    t74 = t1*t68
    t75 = t13*t74
    t76 = q4z*t19
    t77 = t23*t70
    t78 = -b4y - t73 + t75 + t76 + t77 + y
    t79 = Rb*ca.cos(beta4)
    t80 = t16*t74
    t81 = q4z*t28
    t82 = t30*t70
    t83 = -b4x - t79 + t80 + t81 + t82 + x
    t84 = q5z*t2
    t85 = Rp*ca.cos(pi5) + q5x
    t86 = t4*t85
    t87 = Rp*ca.sin(pi5) + q5y
    t88 = t87*t9
    t89 = -b5z + t84 - t86 + t88 + z
    t90 = Rb*ca.sin(beta5)
    t91 = t1*t85
    t92 = t13*t91
    t93 = q5z*t19
    t94 = t23*t87
    t95 = -b5y - t90 + t92 + t93 + t94 + y
    t96 = Rb*ca.cos(beta5)
    t97 = t16*t91
    t98 = q5z*t28
    t99 = t30*t87
    t100 = -b5x - t96 + t97 + t98 + t99 + x
    t101 = q6z*t2
    t102 = Rp*ca.cos(pi6) + q6x
    t103 = t102*t4
    t104 = Rp*ca.sin(pi6) + q6y
    t105 = t104*t9
    t106 = -b6z + t101 - t103 + t105 + z
    t107 = Rb*ca.sin(beta6)
    t108 = t1*t102
    t109 = t108*t13
    t110 = q6z*t19
    t111 = t104*t23
    t112 = -b6y - t107 + t109 + t110 + t111 + y
    t113 = Rb*ca.cos(beta6)
    t114 = t108*t16
    t115 = q6z*t28
    t116 = t104*t30
    t117 = -b6x - t113 + t114 + t115 + t116 + x
    t118 = 2*x
    t119 = 2*t27 + 2*t29 + 2*t31
    t120 = 2*y
    t121 = 2*t15
    t122 = 2*z
    t123 = 2*t6
    t124 = 2*q1z
    t125 = -t30
    t126 = 2*t7
    t127 = -t23
    t128 = t0*t4
    t129 = t4*t8
    t130 = t1*t124
    t131 = t1*t126
    t132 = -t19
    t133 = 2*t46 + 2*t47 + 2*t48
    t134 = 2*t41
    t135 = 2*t35
    t136 = 2*q2z
    t137 = 2*t36
    t138 = t1*t136
    t139 = t1*t137
    t140 = 2*t63 + 2*t64 + 2*t65
    t141 = 2*t58
    t142 = 2*t52
    t143 = 2*q3z
    t144 = 2*t53
    t145 = t1*t143
    t146 = t1*t144
    t147 = 2*t80 + 2*t81 + 2*t82
    t148 = 2*t75
    t149 = 2*t69
    t150 = 2*q4z
    t151 = 2*t70
    t152 = t1*t150
    t153 = t1*t151
    t154 = 2*t97 + 2*t98 + 2*t99
    t155 = 2*t92
    t156 = 2*t86
    t157 = 2*q5z
    t158 = 2*t87
    t159 = t1*t157
    t160 = t1*t158
    t161 = 2*t114 + 2*t115 + 2*t116
    t162 = 2*t109
    t163 = 2*t103
    t164 = 2*q6z
    t165 = 2*t104
    t166 = t1*t164
    t167 = t1*t165
    f = ca.vertcat(-L1**2 + t11**2 + t25**2 + t32**2, -L2**2 + t38**2 + t44**2 + t49**2, -L3**2 + t55**2 + t61**2 + t66**2, -L4**2 + t72**2 + t78**2 + t83**2, -L5**2 + t100**2 + t89**2 + t95**2, -L6**2 + t106**2 + t112**2 + t117**2)
    f_P = ca.vertcat(
        ca.horzcat(-2*b1x + t118 + t119 - 2*t26, -2*b1y - 2*t12 + t120 + t121 + 2*t20 + 2*t24, -2*b1z + 2*t10 + t122 - t123 + 2*t3, t11*(2*t0*t1*t7 - t124*t9) + t25*(t124*t127 + t126*t19) + t32*(t124*t125 + t126*t28), t11*(-t124*t128 - t126*t129 - 2*t14) + t25*(-t123*t13 + t130*t18 + t131*t22) + t32*(-t123*t16 + t130*t21 + t131*t17), t119*t25 + t32*(-t121 + t124*t132 + t126*t127)),
        ca.horzcat(-2*b2x + t118 + t133 - 2*t45, -2*b2y + t120 + t134 - 2*t39 + 2*t42 + 2*t43, -2*b2z + t122 - t135 + 2*t33 + 2*t37, t38*(2*t0*t1*t36 - t136*t9) + t44*(t127*t136 + t137*t19) + t49*(t125*t136 + t137*t28), t38*(-t128*t136 - t129*t137 - 2*t40) + t44*(-t13*t135 + t138*t18 + t139*t22) + t49*(-t135*t16 + t138*t21 + t139*t17), t133*t44 + t49*(t127*t137 + t132*t136 - t134)),
        ca.horzcat(-2*b3x + t118 + t140 - 2*t62, -2*b3y + t120 + t141 - 2*t56 + 2*t59 + 2*t60, -2*b3z + t122 - t142 + 2*t50 + 2*t54, t55*(2*t0*t1*t53 - t143*t9) + t61*(t127*t143 + t144*t19) + t66*(t125*t143 + t144*t28), t55*(-t128*t143 - t129*t144 - 2*t57) + t61*(-t13*t142 + t145*t18 + t146*t22) + t66*(-t142*t16 + t145*t21 + t146*t17), t140*t61 + t66*(t127*t144 + t132*t143 - t141)),
        ca.horzcat(-2*b4x + t118 + t147 - 2*t79, -2*b4y + t120 + t148 - 2*t73 + 2*t76 + 2*t77, -2*b4z + t122 - t149 + 2*t67 + 2*t71, t72*(2*t0*t1*t70 - t150*t9) + t78*(t127*t150 + t151*t19) + t83*(t125*t150 + t151*t28), t72*(-t128*t150 - t129*t151 - 2*t74) + t78*(-t13*t149 + t152*t18 + t153*t22) + t83*(-t149*t16 + t152*t21 + t153*t17), t147*t78 + t83*(t127*t151 + t132*t150 - t148)),
        ca.horzcat(-2*b5x + t118 + t154 - 2*t96, -2*b5y + t120 + t155 - 2*t90 + 2*t93 + 2*t94, -2*b5z + t122 - t156 + 2*t84 + 2*t88, t100*(t125*t157 + t158*t28) + t89*(2*t0*t1*t87 - t157*t9) + t95*(t127*t157 + t158*t19), t100*(-t156*t16 + t159*t21 + t160*t17) + t89*(-t128*t157 - t129*t158 - 2*t91) + t95*(-t13*t156 + t159*t18 + t160*t22), t100*(t127*t158 + t132*t157 - t155) + t154*t95),
        ca.horzcat(-2*b6x - 2*t113 + t118 + t161, -2*b6y - 2*t107 + 2*t110 + 2*t111 + t120 + t162, -2*b6z + 2*t101 + 2*t105 + t122 - t163, t106*(2*t0*t1*t104 - t164*t9) + t112*(t127*t164 + t165*t19) + t117*(t125*t164 + t165*t28), t106*(-2*t108 - t128*t164 - t129*t165) + t112*(-t13*t163 + t166*t18 + t167*t22) + t117*(-t16*t163 + t166*t21 + t167*t17), t112*t161 + t117*(t127*t165 + t132*t164 - t162)),
    )
    return (f, f_P,)


def _fk_start(g):
    """Start pose of the forward kinematics' Newton steps."""
    z_home = g[2]
    P0 = ca.vertcat(0, 0, z_home, 0, 0, 0)
    return (P0,)


def _fk(theta, g):
    """Forward kinematics: 7 Newton steps on the loop closure from fk_start; NaN where max|f| > 1e-06 then."""
    P = _fk_start(g)[0]
    for _ in range(7):
        f, f_P = _fk_residual(P, theta, g)
        P = P - ca.solve(f_P, f)
    f = _fk_residual(P, theta, g)[0]
    ok = ca.mmax(ca.fabs(f)) <= 1e-06
    P = ca.if_else(ok, P, ca.DM.nan(P.numel(), 1))
    return (P,)


def _transmission(P, theta, g):
    """Singularity indicators: |s| >= margin away from a singular configuration."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    Rb = g[0]
    Rp = g[1]
    z_home = g[2]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    a0_0 = ca.cos(yaw)
    a0_1 = Rp*ca.cos(pi1) + q1x
    a0_2 = ca.cos(pitch)
    a0_3 = a0_1*a0_2
    a0_4 = ca.sin(roll)
    a0_5 = ca.sin(yaw)
    a0_6 = a0_4*a0_5
    a0_7 = ca.sin(pitch)
    a0_8 = ca.cos(roll)
    a0_9 = a0_0*a0_8
    a0_10 = a0_6 + a0_7*a0_9
    a0_11 = Rp*ca.sin(pi1) + q1y
    a0_12 = a0_5*a0_8
    a0_13 = a0_0*a0_4
    a0_14 = -a0_12 + a0_13*a0_7
    a0_15 = a0_0*a0_3 + a0_10*q1z + a0_11*a0_14
    a0_16 = -Rb*ca.cos(beta1) + a0_15 - b1x + x
    a0_17 = a0_2*a0_8
    a0_18 = a0_2*a0_4
    a0_19 = -a0_1*a0_7 + a0_11*a0_18 + a0_17*q1z
    a0_20 = a0_19 - b1z + z
    a0_21 = a0_12*a0_7 - a0_13
    a0_22 = a0_6*a0_7 + a0_9
    a0_23 = a0_11*a0_22 + a0_21*q1z + a0_3*a0_5
    a0_24 = -Rb*ca.sin(beta1) + a0_23 - b1y + y
    a0_25 = 1/ca.sqrt(a0_16**2 + a0_20**2 + a0_24**2)
    a0_26 = a0_16*a0_25
    a0_27 = a0_24*a0_25
    a0_28 = a0_20*a0_25
    a0_29 = (1/100)*a0_28
    a0_30 = Rp*ca.cos(pi2) + q2x
    a0_31 = a0_2*a0_30
    a0_32 = Rp*ca.sin(pi2) + q2y
    a0_33 = a0_0*a0_31 + a0_10*q2z + a0_14*a0_32
    a0_34 = -Rb*ca.cos(beta2) + a0_33 - b2x + x
    a0_35 = a0_17*q2z + a0_18*a0_32 - a0_30*a0_7
    a0_36 = a0_35 - b2z + z
    a0_37 = a0_21*q2z + a0_22*a0_32 + a0_31*a0_5
    a0_38 = -Rb*ca.sin(beta2) + a0_37 - b2y + y
    a0_39 = 1/ca.sqrt(a0_34**2 + a0_36**2 + a0_38**2)
    a0_40 = a0_34*a0_39
    a0_41 = a0_38*a0_39
    a0_42 = a0_36*a0_39
    a0_43 = (1/100)*a0_42
    a0_44 = Rp*ca.cos(pi3) + q3x
    a0_45 = a0_2*a0_44
    a0_46 = Rp*ca.sin(pi3) + q3y
    a0_47 = a0_0*a0_45 + a0_10*q3z + a0_14*a0_46
    a0_48 = -Rb*ca.cos(beta3) + a0_47 - b3x + x
    a0_49 = a0_17*q3z + a0_18*a0_46 - a0_44*a0_7
    a0_50 = a0_49 - b3z + z
    a0_51 = a0_21*q3z + a0_22*a0_46 + a0_45*a0_5
    a0_52 = -Rb*ca.sin(beta3) + a0_51 - b3y + y
    a0_53 = 1/ca.sqrt(a0_48**2 + a0_50**2 + a0_52**2)
    a0_54 = a0_48*a0_53
    a0_55 = a0_52*a0_53
    a0_56 = a0_50*a0_53
    a0_57 = (1/100)*a0_56
    a0_58 = Rp*ca.cos(pi4) + q4x
    a0_59 = a0_2*a0_58
    a0_60 = Rp*ca.sin(pi4) + q4y
    a0_61 = a0_0*a0_59 + a0_10*q4z + a0_14*a0_60
    a0_62 = -Rb*ca.cos(beta4) + a0_61 - b4x + x
    a0_63 = a0_17*q4z + a0_18*a0_60 - a0_58*a0_7
    a0_64 = a0_63 - b4z + z
    a0_65 = a0_21*q4z + a0_22*a0_60 + a0_5*a0_59
    a0_66 = -Rb*ca.sin(beta4) + a0_65 - b4y + y
    a0_67 = 1/ca.sqrt(a0_62**2 + a0_64**2 + a0_66**2)
    a0_68 = a0_62*a0_67
    a0_69 = a0_66*a0_67
    a0_70 = a0_64*a0_67
    a0_71 = (1/100)*a0_70
    a0_72 = Rp*ca.cos(pi5) + q5x
    a0_73 = a0_2*a0_72
    a0_74 = Rp*ca.sin(pi5) + q5y
    a0_75 = a0_0*a0_73 + a0_10*q5z + a0_14*a0_74
    a0_76 = -Rb*ca.cos(beta5) + a0_75 - b5x + x
    a0_77 = a0_17*q5z + a0_18*a0_74 - a0_7*a0_72
    a0_78 = a0_77 - b5z + z
    a0_79 = a0_21*q5z + a0_22*a0_74 + a0_5*a0_73
    a0_80 = -Rb*ca.sin(beta5) + a0_79 - b5y + y
    a0_81 = 1/ca.sqrt(a0_76**2 + a0_78**2 + a0_80**2)
    a0_82 = a0_76*a0_81
    a0_83 = a0_80*a0_81
    a0_84 = a0_78*a0_81
    a0_85 = (1/100)*a0_84
    a0_86 = Rp*ca.cos(pi6) + q6x
    a0_87 = a0_2*a0_86
    a0_88 = Rp*ca.sin(pi6) + q6y
    a0_89 = a0_0*a0_87 + a0_10*q6z + a0_14*a0_88
    a0_90 = -Rb*ca.cos(beta6) + a0_89 - b6x + x
    a0_91 = a0_17*q6z + a0_18*a0_88 - a0_7*a0_86
    a0_92 = a0_91 - b6z + z
    a0_93 = a0_21*q6z + a0_22*a0_88 + a0_5*a0_87
    a0_94 = -Rb*ca.sin(beta6) + a0_93 - b6y + y
    a0_95 = 1/ca.sqrt(a0_90**2 + a0_92**2 + a0_94**2)
    a0_96 = a0_90*a0_95
    a0_97 = a0_94*a0_95
    a0_98 = a0_92*a0_95
    a0_99 = (1/100)*a0_98
    A0 = ca.vertcat(
        ca.horzcat(a0_26, a0_27, a0_28, -1/100*a0_19*a0_27 + a0_23*a0_29, -a0_15*a0_29 + (1/100)*a0_16*a0_19*a0_25, (1/100)*a0_15*a0_24*a0_25 - 1/100*a0_23*a0_26),
        ca.horzcat(a0_40, a0_41, a0_42, -1/100*a0_35*a0_41 + a0_37*a0_43, -a0_33*a0_43 + (1/100)*a0_34*a0_35*a0_39, (1/100)*a0_33*a0_38*a0_39 - 1/100*a0_37*a0_40),
        ca.horzcat(a0_54, a0_55, a0_56, -1/100*a0_49*a0_55 + a0_51*a0_57, -a0_47*a0_57 + (1/100)*a0_48*a0_49*a0_53, (1/100)*a0_47*a0_52*a0_53 - 1/100*a0_51*a0_54),
        ca.horzcat(a0_68, a0_69, a0_70, -1/100*a0_63*a0_69 + a0_65*a0_71, -a0_61*a0_71 + (1/100)*a0_62*a0_63*a0_67, (1/100)*a0_61*a0_66*a0_67 - 1/100*a0_65*a0_68),
        ca.horzcat(a0_82, a0_83, a0_84, -1/100*a0_77*a0_83 + a0_79*a0_85, -a0_75*a0_85 + (1/100)*a0_76*a0_77*a0_81, (1/100)*a0_75*a0_80*a0_81 - 1/100*a0_79*a0_82),
        ca.horzcat(a0_96, a0_97, a0_98, -1/100*a0_91*a0_97 + a0_93*a0_99, -a0_89*a0_99 + (1/100)*a0_90*a0_91*a0_95, (1/100)*a0_89*a0_94*a0_95 - 1/100*a0_93*a0_96),
    )
    det_M = ca.det(A0)
    a1_0 = ca.cos(pi1)
    a1_1 = -Rb*ca.cos(beta1) + Rp*a1_0 - b1x + q1x
    a1_2 = -b1z + q1z + z_home
    a1_3 = ca.sin(pi1)
    a1_4 = -Rb*ca.sin(beta1) + Rp*a1_3 - b1y + q1y
    a1_5 = 1/ca.sqrt(a1_1**2 + a1_2**2 + a1_4**2)
    a1_6 = a1_1*a1_5
    a1_7 = a1_4*a1_5
    a1_8 = a1_2*a1_5
    a1_9 = Rp*a1_3 + q1y
    a1_10 = (1/100)*q1z
    a1_11 = Rp*a1_0 + q1x
    a1_12 = ca.cos(pi2)
    a1_13 = -Rb*ca.cos(beta2) + Rp*a1_12 - b2x + q2x
    a1_14 = -b2z + q2z + z_home
    a1_15 = ca.sin(pi2)
    a1_16 = -Rb*ca.sin(beta2) + Rp*a1_15 - b2y + q2y
    a1_17 = 1/ca.sqrt(a1_13**2 + a1_14**2 + a1_16**2)
    a1_18 = a1_13*a1_17
    a1_19 = a1_16*a1_17
    a1_20 = a1_14*a1_17
    a1_21 = Rp*a1_15 + q2y
    a1_22 = (1/100)*q2z
    a1_23 = Rp*a1_12 + q2x
    a1_24 = ca.cos(pi3)
    a1_25 = -Rb*ca.cos(beta3) + Rp*a1_24 - b3x + q3x
    a1_26 = -b3z + q3z + z_home
    a1_27 = ca.sin(pi3)
    a1_28 = -Rb*ca.sin(beta3) + Rp*a1_27 - b3y + q3y
    a1_29 = 1/ca.sqrt(a1_25**2 + a1_26**2 + a1_28**2)
    a1_30 = a1_25*a1_29
    a1_31 = a1_28*a1_29
    a1_32 = a1_26*a1_29
    a1_33 = Rp*a1_27 + q3y
    a1_34 = (1/100)*q3z
    a1_35 = Rp*a1_24 + q3x
    a1_36 = ca.cos(pi4)
    a1_37 = -Rb*ca.cos(beta4) + Rp*a1_36 - b4x + q4x
    a1_38 = -b4z + q4z + z_home
    a1_39 = ca.sin(pi4)
    a1_40 = -Rb*ca.sin(beta4) + Rp*a1_39 - b4y + q4y
    a1_41 = 1/ca.sqrt(a1_37**2 + a1_38**2 + a1_40**2)
    a1_42 = a1_37*a1_41
    a1_43 = a1_40*a1_41
    a1_44 = a1_38*a1_41
    a1_45 = Rp*a1_39 + q4y
    a1_46 = (1/100)*q4z
    a1_47 = Rp*a1_36 + q4x
    a1_48 = ca.cos(pi5)
    a1_49 = -Rb*ca.cos(beta5) + Rp*a1_48 - b5x + q5x
    a1_50 = -b5z + q5z + z_home
    a1_51 = ca.sin(pi5)
    a1_52 = -Rb*ca.sin(beta5) + Rp*a1_51 - b5y + q5y
    a1_53 = 1/ca.sqrt(a1_49**2 + a1_50**2 + a1_52**2)
    a1_54 = a1_49*a1_53
    a1_55 = a1_52*a1_53
    a1_56 = a1_50*a1_53
    a1_57 = Rp*a1_51 + q5y
    a1_58 = (1/100)*q5z
    a1_59 = Rp*a1_48 + q5x
    a1_60 = ca.cos(pi6)
    a1_61 = -Rb*ca.cos(beta6) + Rp*a1_60 - b6x + q6x
    a1_62 = -b6z + q6z + z_home
    a1_63 = ca.sin(pi6)
    a1_64 = -Rb*ca.sin(beta6) + Rp*a1_63 - b6y + q6y
    a1_65 = 1/ca.sqrt(a1_61**2 + a1_62**2 + a1_64**2)
    a1_66 = a1_61*a1_65
    a1_67 = a1_64*a1_65
    a1_68 = a1_62*a1_65
    a1_69 = Rp*a1_63 + q6y
    a1_70 = (1/100)*q6z
    a1_71 = Rp*a1_60 + q6x
    A1 = ca.vertcat(
        ca.horzcat(a1_6, a1_7, a1_8, -a1_10*a1_7 + (1/100)*a1_2*a1_5*a1_9, a1_10*a1_6 - 1/100*a1_11*a1_8, (1/100)*a1_11*a1_4*a1_5 - 1/100*a1_6*a1_9),
        ca.horzcat(a1_18, a1_19, a1_20, (1/100)*a1_14*a1_17*a1_21 - a1_19*a1_22, a1_18*a1_22 - 1/100*a1_20*a1_23, (1/100)*a1_16*a1_17*a1_23 - 1/100*a1_18*a1_21),
        ca.horzcat(a1_30, a1_31, a1_32, (1/100)*a1_26*a1_29*a1_33 - a1_31*a1_34, a1_30*a1_34 - 1/100*a1_32*a1_35, (1/100)*a1_28*a1_29*a1_35 - 1/100*a1_30*a1_33),
        ca.horzcat(a1_42, a1_43, a1_44, (1/100)*a1_38*a1_41*a1_45 - a1_43*a1_46, a1_42*a1_46 - 1/100*a1_44*a1_47, (1/100)*a1_40*a1_41*a1_47 - 1/100*a1_42*a1_45),
        ca.horzcat(a1_54, a1_55, a1_56, (1/100)*a1_50*a1_53*a1_57 - a1_55*a1_58, a1_54*a1_58 - 1/100*a1_56*a1_59, (1/100)*a1_52*a1_53*a1_59 - 1/100*a1_54*a1_57),
        ca.horzcat(a1_66, a1_67, a1_68, (1/100)*a1_62*a1_65*a1_69 - a1_67*a1_70, a1_66*a1_70 - 1/100*a1_68*a1_71, (1/100)*a1_64*a1_65*a1_71 - 1/100*a1_66*a1_69),
    )
    det_M_home = ca.det(A1)
    s = ca.vertcat(det_M/det_M_home)
    return (s,)


def _pose_error_jacobian(P, theta, g):
    """dP/d(robot source errors L1 L2 L3 L4 L5 L6 b1x b1y b1z b2x b2y b2z b3x b3y b3z b4x b4y b4z b5x b5y b5z b6x b6y b6z q1x q1y q1z q2x q2y q2z q3x q3y q3z q4x q4y q4z q5x q5y q5z q6x q6y q6z), per rad or mm (implicit differentiation)."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    L1 = theta[0]
    L2 = theta[1]
    L3 = theta[2]
    L4 = theta[3]
    L5 = theta[4]
    L6 = theta[5]
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    a0_0 = 2*x
    a0_1 = Rb*ca.cos(beta1)
    a0_2 = ca.cos(yaw)
    a0_3 = Rp*ca.cos(pi1) + q1x
    a0_4 = ca.cos(pitch)
    a0_5 = a0_3*a0_4
    a0_6 = a0_2*a0_5
    a0_7 = ca.sin(roll)
    a0_8 = ca.sin(yaw)
    a0_9 = a0_7*a0_8
    a0_10 = ca.sin(pitch)
    a0_11 = ca.cos(roll)
    a0_12 = a0_11*a0_2
    a0_13 = a0_10*a0_12
    a0_14 = a0_13 + a0_9
    a0_15 = a0_14*q1z
    a0_16 = Rp*ca.sin(pi1) + q1y
    a0_17 = a0_11*a0_8
    a0_18 = a0_2*a0_7
    a0_19 = a0_10*a0_18
    a0_20 = -a0_17 + a0_19
    a0_21 = a0_16*a0_20
    a0_22 = 2*a0_15 + 2*a0_21 + 2*a0_6
    a0_23 = a0_0 - 2*a0_1 + a0_22 - 2*b1x
    a0_24 = 2*y
    a0_25 = Rb*ca.sin(beta1)
    a0_26 = a0_5*a0_8
    a0_27 = 2*a0_26
    a0_28 = a0_10*a0_17
    a0_29 = -a0_18 + a0_28
    a0_30 = a0_29*q1z
    a0_31 = a0_10*a0_9
    a0_32 = a0_12 + a0_31
    a0_33 = a0_16*a0_32
    a0_34 = a0_24 - 2*a0_25 + a0_27 + 2*a0_30 + 2*a0_33 - 2*b1y
    a0_35 = 2*z
    a0_36 = 2*q1z
    a0_37 = a0_11*a0_4
    a0_38 = a0_10*a0_3
    a0_39 = 2*a0_38
    a0_40 = 2*a0_16
    a0_41 = a0_4*a0_7
    a0_42 = a0_35 + a0_36*a0_37 - a0_39 + a0_40*a0_41 - 2*b1z
    a0_43 = a0_16*a0_41 + a0_37*q1z - a0_38 - b1z + z
    a0_44 = -a0_20
    a0_45 = -a0_1 + a0_15 + a0_21 + a0_6 - b1x + x
    a0_46 = -a0_32
    a0_47 = -a0_25 + a0_26 + a0_30 + a0_33 - b1y + y
    a0_48 = a0_10*a0_11
    a0_49 = a0_10*a0_7
    a0_50 = a0_36*a0_4
    a0_51 = a0_4*a0_40
    a0_52 = -a0_29
    a0_53 = Rb*ca.cos(beta2)
    a0_54 = Rp*ca.cos(pi2) + q2x
    a0_55 = a0_4*a0_54
    a0_56 = a0_2*a0_55
    a0_57 = a0_14*q2z
    a0_58 = Rp*ca.sin(pi2) + q2y
    a0_59 = a0_20*a0_58
    a0_60 = 2*a0_56 + 2*a0_57 + 2*a0_59
    a0_61 = a0_0 - 2*a0_53 + a0_60 - 2*b2x
    a0_62 = Rb*ca.sin(beta2)
    a0_63 = a0_55*a0_8
    a0_64 = 2*a0_63
    a0_65 = a0_29*q2z
    a0_66 = a0_32*a0_58
    a0_67 = a0_24 - 2*a0_62 + a0_64 + 2*a0_65 + 2*a0_66 - 2*b2y
    a0_68 = 2*q2z
    a0_69 = a0_10*a0_54
    a0_70 = 2*a0_69
    a0_71 = 2*a0_58
    a0_72 = a0_35 + a0_37*a0_68 + a0_41*a0_71 - a0_70 - 2*b2z
    a0_73 = a0_37*q2z + a0_41*a0_58 - a0_69 - b2z + z
    a0_74 = -a0_53 + a0_56 + a0_57 + a0_59 - b2x + x
    a0_75 = -a0_62 + a0_63 + a0_65 + a0_66 - b2y + y
    a0_76 = a0_4*a0_68
    a0_77 = a0_4*a0_71
    a0_78 = Rb*ca.cos(beta3)
    a0_79 = Rp*ca.cos(pi3) + q3x
    a0_80 = a0_4*a0_79
    a0_81 = a0_2*a0_80
    a0_82 = a0_14*q3z
    a0_83 = Rp*ca.sin(pi3) + q3y
    a0_84 = a0_20*a0_83
    a0_85 = 2*a0_81 + 2*a0_82 + 2*a0_84
    a0_86 = a0_0 - 2*a0_78 + a0_85 - 2*b3x
    a0_87 = Rb*ca.sin(beta3)
    a0_88 = a0_8*a0_80
    a0_89 = 2*a0_88
    a0_90 = a0_29*q3z
    a0_91 = a0_32*a0_83
    a0_92 = a0_24 - 2*a0_87 + a0_89 + 2*a0_90 + 2*a0_91 - 2*b3y
    a0_93 = 2*q3z
    a0_94 = a0_10*a0_79
    a0_95 = 2*a0_94
    a0_96 = 2*a0_83
    a0_97 = a0_35 + a0_37*a0_93 + a0_41*a0_96 - a0_95 - 2*b3z
    a0_98 = a0_37*q3z + a0_41*a0_83 - a0_94 - b3z + z
    a0_99 = -a0_78 + a0_81 + a0_82 + a0_84 - b3x + x
    a0_100 = -a0_87 + a0_88 + a0_90 + a0_91 - b3y + y
    a0_101 = a0_4*a0_93
    a0_102 = a0_4*a0_96
    a0_103 = Rb*ca.cos(beta4)
    a0_104 = Rp*ca.cos(pi4) + q4x
    a0_105 = a0_104*a0_4
    a0_106 = a0_105*a0_2
    a0_107 = a0_14*q4z
    a0_108 = Rp*ca.sin(pi4) + q4y
    a0_109 = a0_108*a0_20
    a0_110 = 2*a0_106 + 2*a0_107 + 2*a0_109
    a0_111 = a0_0 - 2*a0_103 + a0_110 - 2*b4x
    a0_112 = Rb*ca.sin(beta4)
    a0_113 = a0_105*a0_8
    a0_114 = 2*a0_113
    a0_115 = a0_29*q4z
    a0_116 = a0_108*a0_32
    a0_117 = -2*a0_112 + a0_114 + 2*a0_115 + 2*a0_116 + a0_24 - 2*b4y
    a0_118 = 2*q4z
    a0_119 = a0_10*a0_104
    a0_120 = 2*a0_119
    a0_121 = 2*a0_108
    a0_122 = a0_118*a0_37 - a0_120 + a0_121*a0_41 + a0_35 - 2*b4z
    a0_123 = a0_108*a0_41 - a0_119 + a0_37*q4z - b4z + z
    a0_124 = -a0_103 + a0_106 + a0_107 + a0_109 - b4x + x
    a0_125 = -a0_112 + a0_113 + a0_115 + a0_116 - b4y + y
    a0_126 = a0_118*a0_4
    a0_127 = a0_121*a0_4
    a0_128 = Rb*ca.cos(beta5)
    a0_129 = Rp*ca.cos(pi5) + q5x
    a0_130 = a0_129*a0_4
    a0_131 = a0_130*a0_2
    a0_132 = a0_14*q5z
    a0_133 = Rp*ca.sin(pi5) + q5y
    a0_134 = a0_133*a0_20
    a0_135 = 2*a0_131 + 2*a0_132 + 2*a0_134
    a0_136 = a0_0 - 2*a0_128 + a0_135 - 2*b5x
    a0_137 = Rb*ca.sin(beta5)
    a0_138 = a0_130*a0_8
    a0_139 = 2*a0_138
    a0_140 = a0_29*q5z
    a0_141 = a0_133*a0_32
    a0_142 = -2*a0_137 + a0_139 + 2*a0_140 + 2*a0_141 + a0_24 - 2*b5y
    a0_143 = 2*q5z
    a0_144 = a0_10*a0_129
    a0_145 = 2*a0_144
    a0_146 = 2*a0_133
    a0_147 = a0_143*a0_37 - a0_145 + a0_146*a0_41 + a0_35 - 2*b5z
    a0_148 = a0_133*a0_41 - a0_144 + a0_37*q5z - b5z + z
    a0_149 = -a0_128 + a0_131 + a0_132 + a0_134 - b5x + x
    a0_150 = -a0_137 + a0_138 + a0_140 + a0_141 - b5y + y
    a0_151 = a0_143*a0_4
    a0_152 = a0_146*a0_4
    a0_153 = Rb*ca.cos(beta6)
    a0_154 = Rp*ca.cos(pi6) + q6x
    a0_155 = a0_154*a0_4
    a0_156 = a0_155*a0_2
    a0_157 = a0_14*q6z
    a0_158 = Rp*ca.sin(pi6) + q6y
    a0_159 = a0_158*a0_20
    a0_160 = 2*a0_156 + 2*a0_157 + 2*a0_159
    a0_161 = a0_0 - 2*a0_153 + a0_160 - 2*b6x
    a0_162 = Rb*ca.sin(beta6)
    a0_163 = a0_155*a0_8
    a0_164 = 2*a0_163
    a0_165 = a0_29*q6z
    a0_166 = a0_158*a0_32
    a0_167 = -2*a0_162 + a0_164 + 2*a0_165 + 2*a0_166 + a0_24 - 2*b6y
    a0_168 = 2*q6z
    a0_169 = a0_10*a0_154
    a0_170 = 2*a0_169
    a0_171 = 2*a0_158
    a0_172 = a0_168*a0_37 - a0_170 + a0_171*a0_41 + a0_35 - 2*b6z
    a0_173 = a0_158*a0_41 - a0_169 + a0_37*q6z - b6z + z
    a0_174 = -a0_153 + a0_156 + a0_157 + a0_159 - b6x + x
    a0_175 = -a0_162 + a0_163 + a0_165 + a0_166 - b6y + y
    a0_176 = a0_168*a0_4
    a0_177 = a0_171*a0_4
    a0_178 = 2*a0_4
    a0_179 = a0_178*a0_8
    a0_180 = a0_178*a0_2
    a0_181 = 2*a0_43
    a0_182 = 2*a0_12 + 2*a0_31
    a0_183 = -2*a0_17 + 2*a0_19
    a0_184 = -2*a0_18 + 2*a0_28
    a0_185 = 2*a0_13 + 2*a0_9
    a0_186 = 2*a0_73
    a0_187 = 2*a0_98
    a0_188 = 2*a0_123
    a0_189 = 2*a0_148
    a0_190 = 2*a0_173
    A0 = ca.vertcat(
        ca.horzcat(a0_23, a0_34, a0_42, a0_43*(2*a0_11*a0_16*a0_4 - a0_36*a0_41) + a0_45*(a0_14*a0_40 + a0_36*a0_44) + a0_47*(a0_29*a0_40 + a0_36*a0_46), a0_43*(-a0_36*a0_48 - a0_40*a0_49 - 2*a0_5) + a0_45*(a0_12*a0_50 + a0_18*a0_51 - a0_2*a0_39) + a0_47*(a0_17*a0_50 - a0_39*a0_8 + a0_51*a0_9), a0_22*a0_47 + a0_45*(-a0_27 + a0_36*a0_52 + a0_40*a0_46)),
        ca.horzcat(a0_61, a0_67, a0_72, a0_73*(2*a0_11*a0_4*a0_58 - a0_41*a0_68) + a0_74*(a0_14*a0_71 + a0_44*a0_68) + a0_75*(a0_29*a0_71 + a0_46*a0_68), a0_73*(-a0_48*a0_68 - a0_49*a0_71 - 2*a0_55) + a0_74*(a0_12*a0_76 + a0_18*a0_77 - a0_2*a0_70) + a0_75*(a0_17*a0_76 - a0_70*a0_8 + a0_77*a0_9), a0_60*a0_75 + a0_74*(a0_46*a0_71 + a0_52*a0_68 - a0_64)),
        ca.horzcat(a0_86, a0_92, a0_97, a0_100*(a0_29*a0_96 + a0_46*a0_93) + a0_98*(2*a0_11*a0_4*a0_83 - a0_41*a0_93) + a0_99*(a0_14*a0_96 + a0_44*a0_93), a0_100*(a0_101*a0_17 + a0_102*a0_9 - a0_8*a0_95) + a0_98*(-a0_48*a0_93 - a0_49*a0_96 - 2*a0_80) + a0_99*(a0_101*a0_12 + a0_102*a0_18 - a0_2*a0_95), a0_100*a0_85 + a0_99*(a0_46*a0_96 + a0_52*a0_93 - a0_89)),
        ca.horzcat(a0_111, a0_117, a0_122, a0_123*(2*a0_108*a0_11*a0_4 - a0_118*a0_41) + a0_124*(a0_118*a0_44 + a0_121*a0_14) + a0_125*(a0_118*a0_46 + a0_121*a0_29), a0_123*(-2*a0_105 - a0_118*a0_48 - a0_121*a0_49) + a0_124*(a0_12*a0_126 - a0_120*a0_2 + a0_127*a0_18) + a0_125*(-a0_120*a0_8 + a0_126*a0_17 + a0_127*a0_9), a0_110*a0_125 + a0_124*(-a0_114 + a0_118*a0_52 + a0_121*a0_46)),
        ca.horzcat(a0_136, a0_142, a0_147, a0_148*(2*a0_11*a0_133*a0_4 - a0_143*a0_41) + a0_149*(a0_14*a0_146 + a0_143*a0_44) + a0_150*(a0_143*a0_46 + a0_146*a0_29), a0_148*(-2*a0_130 - a0_143*a0_48 - a0_146*a0_49) + a0_149*(a0_12*a0_151 - a0_145*a0_2 + a0_152*a0_18) + a0_150*(-a0_145*a0_8 + a0_151*a0_17 + a0_152*a0_9), a0_135*a0_150 + a0_149*(-a0_139 + a0_143*a0_52 + a0_146*a0_46)),
        ca.horzcat(a0_161, a0_167, a0_172, a0_173*(2*a0_11*a0_158*a0_4 - a0_168*a0_41) + a0_174*(a0_14*a0_171 + a0_168*a0_44) + a0_175*(a0_168*a0_46 + a0_171*a0_29), a0_173*(-2*a0_155 - a0_168*a0_48 - a0_171*a0_49) + a0_174*(a0_12*a0_176 - a0_170*a0_2 + a0_177*a0_18) + a0_175*(a0_17*a0_176 - a0_170*a0_8 + a0_177*a0_9), a0_160*a0_175 + a0_174*(-a0_164 + a0_168*a0_52 + a0_171*a0_46)),
    )
    B0 = ca.vertcat(
        ca.horzcat(2*L1, 0, 0, 0, 0, 0, a0_23, a0_34, a0_42, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_43 - a0_179*a0_47 - a0_180*a0_45, -a0_181*a0_41 - a0_182*a0_47 - a0_183*a0_45, -a0_181*a0_37 - a0_184*a0_47 - a0_185*a0_45, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 2*L2, 0, 0, 0, 0, 0, 0, 0, a0_61, a0_67, a0_72, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_73 - a0_179*a0_75 - a0_180*a0_74, -a0_182*a0_75 - a0_183*a0_74 - a0_186*a0_41, -a0_184*a0_75 - a0_185*a0_74 - a0_186*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 2*L3, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_86, a0_92, a0_97, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_98 - a0_100*a0_179 - a0_180*a0_99, -a0_100*a0_182 - a0_183*a0_99 - a0_187*a0_41, -a0_100*a0_184 - a0_185*a0_99 - a0_187*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 2*L4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_111, a0_117, a0_122, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_123 - a0_124*a0_180 - a0_125*a0_179, -a0_124*a0_183 - a0_125*a0_182 - a0_188*a0_41, -a0_124*a0_185 - a0_125*a0_184 - a0_188*a0_37, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 2*L5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_136, a0_142, a0_147, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_148 - a0_149*a0_180 - a0_150*a0_179, -a0_149*a0_183 - a0_150*a0_182 - a0_189*a0_41, -a0_149*a0_185 - a0_150*a0_184 - a0_189*a0_37, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 2*L6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_161, a0_167, a0_172, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_173 - a0_174*a0_180 - a0_175*a0_179, -a0_174*a0_183 - a0_175*a0_182 - a0_190*a0_41, -a0_174*a0_185 - a0_175*a0_184 - a0_190*a0_37),
    )
    X0 = ca.solve(A0, B0)
    J_0_0 = X0[0, 0]
    J_0_1 = X0[0, 1]
    J_0_2 = X0[0, 2]
    J_0_3 = X0[0, 3]
    J_0_4 = X0[0, 4]
    J_0_5 = X0[0, 5]
    J_0_6 = X0[0, 6]
    J_0_7 = X0[0, 7]
    J_0_8 = X0[0, 8]
    J_0_9 = X0[0, 9]
    J_0_10 = X0[0, 10]
    J_0_11 = X0[0, 11]
    J_0_12 = X0[0, 12]
    J_0_13 = X0[0, 13]
    J_0_14 = X0[0, 14]
    J_0_15 = X0[0, 15]
    J_0_16 = X0[0, 16]
    J_0_17 = X0[0, 17]
    J_0_18 = X0[0, 18]
    J_0_19 = X0[0, 19]
    J_0_20 = X0[0, 20]
    J_0_21 = X0[0, 21]
    J_0_22 = X0[0, 22]
    J_0_23 = X0[0, 23]
    J_0_24 = X0[0, 24]
    J_0_25 = X0[0, 25]
    J_0_26 = X0[0, 26]
    J_0_27 = X0[0, 27]
    J_0_28 = X0[0, 28]
    J_0_29 = X0[0, 29]
    J_0_30 = X0[0, 30]
    J_0_31 = X0[0, 31]
    J_0_32 = X0[0, 32]
    J_0_33 = X0[0, 33]
    J_0_34 = X0[0, 34]
    J_0_35 = X0[0, 35]
    J_0_36 = X0[0, 36]
    J_0_37 = X0[0, 37]
    J_0_38 = X0[0, 38]
    J_0_39 = X0[0, 39]
    J_0_40 = X0[0, 40]
    J_0_41 = X0[0, 41]
    J_1_0 = X0[1, 0]
    J_1_1 = X0[1, 1]
    J_1_2 = X0[1, 2]
    J_1_3 = X0[1, 3]
    J_1_4 = X0[1, 4]
    J_1_5 = X0[1, 5]
    J_1_6 = X0[1, 6]
    J_1_7 = X0[1, 7]
    J_1_8 = X0[1, 8]
    J_1_9 = X0[1, 9]
    J_1_10 = X0[1, 10]
    J_1_11 = X0[1, 11]
    J_1_12 = X0[1, 12]
    J_1_13 = X0[1, 13]
    J_1_14 = X0[1, 14]
    J_1_15 = X0[1, 15]
    J_1_16 = X0[1, 16]
    J_1_17 = X0[1, 17]
    J_1_18 = X0[1, 18]
    J_1_19 = X0[1, 19]
    J_1_20 = X0[1, 20]
    J_1_21 = X0[1, 21]
    J_1_22 = X0[1, 22]
    J_1_23 = X0[1, 23]
    J_1_24 = X0[1, 24]
    J_1_25 = X0[1, 25]
    J_1_26 = X0[1, 26]
    J_1_27 = X0[1, 27]
    J_1_28 = X0[1, 28]
    J_1_29 = X0[1, 29]
    J_1_30 = X0[1, 30]
    J_1_31 = X0[1, 31]
    J_1_32 = X0[1, 32]
    J_1_33 = X0[1, 33]
    J_1_34 = X0[1, 34]
    J_1_35 = X0[1, 35]
    J_1_36 = X0[1, 36]
    J_1_37 = X0[1, 37]
    J_1_38 = X0[1, 38]
    J_1_39 = X0[1, 39]
    J_1_40 = X0[1, 40]
    J_1_41 = X0[1, 41]
    J_2_0 = X0[2, 0]
    J_2_1 = X0[2, 1]
    J_2_2 = X0[2, 2]
    J_2_3 = X0[2, 3]
    J_2_4 = X0[2, 4]
    J_2_5 = X0[2, 5]
    J_2_6 = X0[2, 6]
    J_2_7 = X0[2, 7]
    J_2_8 = X0[2, 8]
    J_2_9 = X0[2, 9]
    J_2_10 = X0[2, 10]
    J_2_11 = X0[2, 11]
    J_2_12 = X0[2, 12]
    J_2_13 = X0[2, 13]
    J_2_14 = X0[2, 14]
    J_2_15 = X0[2, 15]
    J_2_16 = X0[2, 16]
    J_2_17 = X0[2, 17]
    J_2_18 = X0[2, 18]
    J_2_19 = X0[2, 19]
    J_2_20 = X0[2, 20]
    J_2_21 = X0[2, 21]
    J_2_22 = X0[2, 22]
    J_2_23 = X0[2, 23]
    J_2_24 = X0[2, 24]
    J_2_25 = X0[2, 25]
    J_2_26 = X0[2, 26]
    J_2_27 = X0[2, 27]
    J_2_28 = X0[2, 28]
    J_2_29 = X0[2, 29]
    J_2_30 = X0[2, 30]
    J_2_31 = X0[2, 31]
    J_2_32 = X0[2, 32]
    J_2_33 = X0[2, 33]
    J_2_34 = X0[2, 34]
    J_2_35 = X0[2, 35]
    J_2_36 = X0[2, 36]
    J_2_37 = X0[2, 37]
    J_2_38 = X0[2, 38]
    J_2_39 = X0[2, 39]
    J_2_40 = X0[2, 40]
    J_2_41 = X0[2, 41]
    J_3_0 = X0[3, 0]
    J_3_1 = X0[3, 1]
    J_3_2 = X0[3, 2]
    J_3_3 = X0[3, 3]
    J_3_4 = X0[3, 4]
    J_3_5 = X0[3, 5]
    J_3_6 = X0[3, 6]
    J_3_7 = X0[3, 7]
    J_3_8 = X0[3, 8]
    J_3_9 = X0[3, 9]
    J_3_10 = X0[3, 10]
    J_3_11 = X0[3, 11]
    J_3_12 = X0[3, 12]
    J_3_13 = X0[3, 13]
    J_3_14 = X0[3, 14]
    J_3_15 = X0[3, 15]
    J_3_16 = X0[3, 16]
    J_3_17 = X0[3, 17]
    J_3_18 = X0[3, 18]
    J_3_19 = X0[3, 19]
    J_3_20 = X0[3, 20]
    J_3_21 = X0[3, 21]
    J_3_22 = X0[3, 22]
    J_3_23 = X0[3, 23]
    J_3_24 = X0[3, 24]
    J_3_25 = X0[3, 25]
    J_3_26 = X0[3, 26]
    J_3_27 = X0[3, 27]
    J_3_28 = X0[3, 28]
    J_3_29 = X0[3, 29]
    J_3_30 = X0[3, 30]
    J_3_31 = X0[3, 31]
    J_3_32 = X0[3, 32]
    J_3_33 = X0[3, 33]
    J_3_34 = X0[3, 34]
    J_3_35 = X0[3, 35]
    J_3_36 = X0[3, 36]
    J_3_37 = X0[3, 37]
    J_3_38 = X0[3, 38]
    J_3_39 = X0[3, 39]
    J_3_40 = X0[3, 40]
    J_3_41 = X0[3, 41]
    J_4_0 = X0[4, 0]
    J_4_1 = X0[4, 1]
    J_4_2 = X0[4, 2]
    J_4_3 = X0[4, 3]
    J_4_4 = X0[4, 4]
    J_4_5 = X0[4, 5]
    J_4_6 = X0[4, 6]
    J_4_7 = X0[4, 7]
    J_4_8 = X0[4, 8]
    J_4_9 = X0[4, 9]
    J_4_10 = X0[4, 10]
    J_4_11 = X0[4, 11]
    J_4_12 = X0[4, 12]
    J_4_13 = X0[4, 13]
    J_4_14 = X0[4, 14]
    J_4_15 = X0[4, 15]
    J_4_16 = X0[4, 16]
    J_4_17 = X0[4, 17]
    J_4_18 = X0[4, 18]
    J_4_19 = X0[4, 19]
    J_4_20 = X0[4, 20]
    J_4_21 = X0[4, 21]
    J_4_22 = X0[4, 22]
    J_4_23 = X0[4, 23]
    J_4_24 = X0[4, 24]
    J_4_25 = X0[4, 25]
    J_4_26 = X0[4, 26]
    J_4_27 = X0[4, 27]
    J_4_28 = X0[4, 28]
    J_4_29 = X0[4, 29]
    J_4_30 = X0[4, 30]
    J_4_31 = X0[4, 31]
    J_4_32 = X0[4, 32]
    J_4_33 = X0[4, 33]
    J_4_34 = X0[4, 34]
    J_4_35 = X0[4, 35]
    J_4_36 = X0[4, 36]
    J_4_37 = X0[4, 37]
    J_4_38 = X0[4, 38]
    J_4_39 = X0[4, 39]
    J_4_40 = X0[4, 40]
    J_4_41 = X0[4, 41]
    J_5_0 = X0[5, 0]
    J_5_1 = X0[5, 1]
    J_5_2 = X0[5, 2]
    J_5_3 = X0[5, 3]
    J_5_4 = X0[5, 4]
    J_5_5 = X0[5, 5]
    J_5_6 = X0[5, 6]
    J_5_7 = X0[5, 7]
    J_5_8 = X0[5, 8]
    J_5_9 = X0[5, 9]
    J_5_10 = X0[5, 10]
    J_5_11 = X0[5, 11]
    J_5_12 = X0[5, 12]
    J_5_13 = X0[5, 13]
    J_5_14 = X0[5, 14]
    J_5_15 = X0[5, 15]
    J_5_16 = X0[5, 16]
    J_5_17 = X0[5, 17]
    J_5_18 = X0[5, 18]
    J_5_19 = X0[5, 19]
    J_5_20 = X0[5, 20]
    J_5_21 = X0[5, 21]
    J_5_22 = X0[5, 22]
    J_5_23 = X0[5, 23]
    J_5_24 = X0[5, 24]
    J_5_25 = X0[5, 25]
    J_5_26 = X0[5, 26]
    J_5_27 = X0[5, 27]
    J_5_28 = X0[5, 28]
    J_5_29 = X0[5, 29]
    J_5_30 = X0[5, 30]
    J_5_31 = X0[5, 31]
    J_5_32 = X0[5, 32]
    J_5_33 = X0[5, 33]
    J_5_34 = X0[5, 34]
    J_5_35 = X0[5, 35]
    J_5_36 = X0[5, 36]
    J_5_37 = X0[5, 37]
    J_5_38 = X0[5, 38]
    J_5_39 = X0[5, 39]
    J_5_40 = X0[5, 40]
    J_5_41 = X0[5, 41]
    J_src = ca.vertcat(
        ca.horzcat(J_0_0, J_0_1, J_0_2, J_0_3, J_0_4, J_0_5, J_0_6, J_0_7, J_0_8, J_0_9, J_0_10, J_0_11, J_0_12, J_0_13, J_0_14, J_0_15, J_0_16, J_0_17, J_0_18, J_0_19, J_0_20, J_0_21, J_0_22, J_0_23, J_0_24, J_0_25, J_0_26, J_0_27, J_0_28, J_0_29, J_0_30, J_0_31, J_0_32, J_0_33, J_0_34, J_0_35, J_0_36, J_0_37, J_0_38, J_0_39, J_0_40, J_0_41),
        ca.horzcat(J_1_0, J_1_1, J_1_2, J_1_3, J_1_4, J_1_5, J_1_6, J_1_7, J_1_8, J_1_9, J_1_10, J_1_11, J_1_12, J_1_13, J_1_14, J_1_15, J_1_16, J_1_17, J_1_18, J_1_19, J_1_20, J_1_21, J_1_22, J_1_23, J_1_24, J_1_25, J_1_26, J_1_27, J_1_28, J_1_29, J_1_30, J_1_31, J_1_32, J_1_33, J_1_34, J_1_35, J_1_36, J_1_37, J_1_38, J_1_39, J_1_40, J_1_41),
        ca.horzcat(J_2_0, J_2_1, J_2_2, J_2_3, J_2_4, J_2_5, J_2_6, J_2_7, J_2_8, J_2_9, J_2_10, J_2_11, J_2_12, J_2_13, J_2_14, J_2_15, J_2_16, J_2_17, J_2_18, J_2_19, J_2_20, J_2_21, J_2_22, J_2_23, J_2_24, J_2_25, J_2_26, J_2_27, J_2_28, J_2_29, J_2_30, J_2_31, J_2_32, J_2_33, J_2_34, J_2_35, J_2_36, J_2_37, J_2_38, J_2_39, J_2_40, J_2_41),
        ca.horzcat(J_3_0, J_3_1, J_3_2, J_3_3, J_3_4, J_3_5, J_3_6, J_3_7, J_3_8, J_3_9, J_3_10, J_3_11, J_3_12, J_3_13, J_3_14, J_3_15, J_3_16, J_3_17, J_3_18, J_3_19, J_3_20, J_3_21, J_3_22, J_3_23, J_3_24, J_3_25, J_3_26, J_3_27, J_3_28, J_3_29, J_3_30, J_3_31, J_3_32, J_3_33, J_3_34, J_3_35, J_3_36, J_3_37, J_3_38, J_3_39, J_3_40, J_3_41),
        ca.horzcat(J_4_0, J_4_1, J_4_2, J_4_3, J_4_4, J_4_5, J_4_6, J_4_7, J_4_8, J_4_9, J_4_10, J_4_11, J_4_12, J_4_13, J_4_14, J_4_15, J_4_16, J_4_17, J_4_18, J_4_19, J_4_20, J_4_21, J_4_22, J_4_23, J_4_24, J_4_25, J_4_26, J_4_27, J_4_28, J_4_29, J_4_30, J_4_31, J_4_32, J_4_33, J_4_34, J_4_35, J_4_36, J_4_37, J_4_38, J_4_39, J_4_40, J_4_41),
        ca.horzcat(J_5_0, J_5_1, J_5_2, J_5_3, J_5_4, J_5_5, J_5_6, J_5_7, J_5_8, J_5_9, J_5_10, J_5_11, J_5_12, J_5_13, J_5_14, J_5_15, J_5_16, J_5_17, J_5_18, J_5_19, J_5_20, J_5_21, J_5_22, J_5_23, J_5_24, J_5_25, J_5_26, J_5_27, J_5_28, J_5_29, J_5_30, J_5_31, J_5_32, J_5_33, J_5_34, J_5_35, J_5_36, J_5_37, J_5_38, J_5_39, J_5_40, J_5_41),
    )
    return (J_src,)


def _error_jacobian(P, theta, g):
    """dP/d(offsets as lengths: lever_i dtheta_i for a revolute joint, ds_i for a prismatic one) (paper Eq. 13 in n dimensions)."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    L1 = theta[0]
    L2 = theta[1]
    L3 = theta[2]
    L4 = theta[3]
    L5 = theta[4]
    L6 = theta[5]
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    a0_0 = 2*x
    a0_1 = Rb*ca.cos(beta1)
    a0_2 = ca.cos(yaw)
    a0_3 = Rp*ca.cos(pi1) + q1x
    a0_4 = ca.cos(pitch)
    a0_5 = a0_3*a0_4
    a0_6 = a0_2*a0_5
    a0_7 = ca.sin(roll)
    a0_8 = ca.sin(yaw)
    a0_9 = a0_7*a0_8
    a0_10 = ca.sin(pitch)
    a0_11 = ca.cos(roll)
    a0_12 = a0_11*a0_2
    a0_13 = a0_10*a0_12
    a0_14 = a0_13 + a0_9
    a0_15 = a0_14*q1z
    a0_16 = Rp*ca.sin(pi1) + q1y
    a0_17 = a0_11*a0_8
    a0_18 = a0_2*a0_7
    a0_19 = a0_10*a0_18
    a0_20 = -a0_17 + a0_19
    a0_21 = a0_16*a0_20
    a0_22 = 2*a0_15 + 2*a0_21 + 2*a0_6
    a0_23 = a0_0 - 2*a0_1 + a0_22 - 2*b1x
    a0_24 = 2*y
    a0_25 = Rb*ca.sin(beta1)
    a0_26 = a0_5*a0_8
    a0_27 = 2*a0_26
    a0_28 = a0_10*a0_17
    a0_29 = -a0_18 + a0_28
    a0_30 = a0_29*q1z
    a0_31 = a0_10*a0_9
    a0_32 = a0_12 + a0_31
    a0_33 = a0_16*a0_32
    a0_34 = a0_24 - 2*a0_25 + a0_27 + 2*a0_30 + 2*a0_33 - 2*b1y
    a0_35 = 2*z
    a0_36 = 2*q1z
    a0_37 = a0_11*a0_4
    a0_38 = a0_10*a0_3
    a0_39 = 2*a0_38
    a0_40 = 2*a0_16
    a0_41 = a0_4*a0_7
    a0_42 = a0_35 + a0_36*a0_37 - a0_39 + a0_40*a0_41 - 2*b1z
    a0_43 = a0_16*a0_41 + a0_37*q1z - a0_38 - b1z + z
    a0_44 = -a0_20
    a0_45 = -a0_1 + a0_15 + a0_21 + a0_6 - b1x + x
    a0_46 = -a0_32
    a0_47 = -a0_25 + a0_26 + a0_30 + a0_33 - b1y + y
    a0_48 = a0_10*a0_11
    a0_49 = a0_10*a0_7
    a0_50 = a0_36*a0_4
    a0_51 = a0_4*a0_40
    a0_52 = -a0_29
    a0_53 = Rb*ca.cos(beta2)
    a0_54 = Rp*ca.cos(pi2) + q2x
    a0_55 = a0_4*a0_54
    a0_56 = a0_2*a0_55
    a0_57 = a0_14*q2z
    a0_58 = Rp*ca.sin(pi2) + q2y
    a0_59 = a0_20*a0_58
    a0_60 = 2*a0_56 + 2*a0_57 + 2*a0_59
    a0_61 = a0_0 - 2*a0_53 + a0_60 - 2*b2x
    a0_62 = Rb*ca.sin(beta2)
    a0_63 = a0_55*a0_8
    a0_64 = 2*a0_63
    a0_65 = a0_29*q2z
    a0_66 = a0_32*a0_58
    a0_67 = a0_24 - 2*a0_62 + a0_64 + 2*a0_65 + 2*a0_66 - 2*b2y
    a0_68 = 2*q2z
    a0_69 = a0_10*a0_54
    a0_70 = 2*a0_69
    a0_71 = 2*a0_58
    a0_72 = a0_35 + a0_37*a0_68 + a0_41*a0_71 - a0_70 - 2*b2z
    a0_73 = a0_37*q2z + a0_41*a0_58 - a0_69 - b2z + z
    a0_74 = -a0_53 + a0_56 + a0_57 + a0_59 - b2x + x
    a0_75 = -a0_62 + a0_63 + a0_65 + a0_66 - b2y + y
    a0_76 = a0_4*a0_68
    a0_77 = a0_4*a0_71
    a0_78 = Rb*ca.cos(beta3)
    a0_79 = Rp*ca.cos(pi3) + q3x
    a0_80 = a0_4*a0_79
    a0_81 = a0_2*a0_80
    a0_82 = a0_14*q3z
    a0_83 = Rp*ca.sin(pi3) + q3y
    a0_84 = a0_20*a0_83
    a0_85 = 2*a0_81 + 2*a0_82 + 2*a0_84
    a0_86 = a0_0 - 2*a0_78 + a0_85 - 2*b3x
    a0_87 = Rb*ca.sin(beta3)
    a0_88 = a0_8*a0_80
    a0_89 = 2*a0_88
    a0_90 = a0_29*q3z
    a0_91 = a0_32*a0_83
    a0_92 = a0_24 - 2*a0_87 + a0_89 + 2*a0_90 + 2*a0_91 - 2*b3y
    a0_93 = 2*q3z
    a0_94 = a0_10*a0_79
    a0_95 = 2*a0_94
    a0_96 = 2*a0_83
    a0_97 = a0_35 + a0_37*a0_93 + a0_41*a0_96 - a0_95 - 2*b3z
    a0_98 = a0_37*q3z + a0_41*a0_83 - a0_94 - b3z + z
    a0_99 = -a0_78 + a0_81 + a0_82 + a0_84 - b3x + x
    a0_100 = -a0_87 + a0_88 + a0_90 + a0_91 - b3y + y
    a0_101 = a0_4*a0_93
    a0_102 = a0_4*a0_96
    a0_103 = Rb*ca.cos(beta4)
    a0_104 = Rp*ca.cos(pi4) + q4x
    a0_105 = a0_104*a0_4
    a0_106 = a0_105*a0_2
    a0_107 = a0_14*q4z
    a0_108 = Rp*ca.sin(pi4) + q4y
    a0_109 = a0_108*a0_20
    a0_110 = 2*a0_106 + 2*a0_107 + 2*a0_109
    a0_111 = a0_0 - 2*a0_103 + a0_110 - 2*b4x
    a0_112 = Rb*ca.sin(beta4)
    a0_113 = a0_105*a0_8
    a0_114 = 2*a0_113
    a0_115 = a0_29*q4z
    a0_116 = a0_108*a0_32
    a0_117 = -2*a0_112 + a0_114 + 2*a0_115 + 2*a0_116 + a0_24 - 2*b4y
    a0_118 = 2*q4z
    a0_119 = a0_10*a0_104
    a0_120 = 2*a0_119
    a0_121 = 2*a0_108
    a0_122 = a0_118*a0_37 - a0_120 + a0_121*a0_41 + a0_35 - 2*b4z
    a0_123 = a0_108*a0_41 - a0_119 + a0_37*q4z - b4z + z
    a0_124 = -a0_103 + a0_106 + a0_107 + a0_109 - b4x + x
    a0_125 = -a0_112 + a0_113 + a0_115 + a0_116 - b4y + y
    a0_126 = a0_118*a0_4
    a0_127 = a0_121*a0_4
    a0_128 = Rb*ca.cos(beta5)
    a0_129 = Rp*ca.cos(pi5) + q5x
    a0_130 = a0_129*a0_4
    a0_131 = a0_130*a0_2
    a0_132 = a0_14*q5z
    a0_133 = Rp*ca.sin(pi5) + q5y
    a0_134 = a0_133*a0_20
    a0_135 = 2*a0_131 + 2*a0_132 + 2*a0_134
    a0_136 = a0_0 - 2*a0_128 + a0_135 - 2*b5x
    a0_137 = Rb*ca.sin(beta5)
    a0_138 = a0_130*a0_8
    a0_139 = 2*a0_138
    a0_140 = a0_29*q5z
    a0_141 = a0_133*a0_32
    a0_142 = -2*a0_137 + a0_139 + 2*a0_140 + 2*a0_141 + a0_24 - 2*b5y
    a0_143 = 2*q5z
    a0_144 = a0_10*a0_129
    a0_145 = 2*a0_144
    a0_146 = 2*a0_133
    a0_147 = a0_143*a0_37 - a0_145 + a0_146*a0_41 + a0_35 - 2*b5z
    a0_148 = a0_133*a0_41 - a0_144 + a0_37*q5z - b5z + z
    a0_149 = -a0_128 + a0_131 + a0_132 + a0_134 - b5x + x
    a0_150 = -a0_137 + a0_138 + a0_140 + a0_141 - b5y + y
    a0_151 = a0_143*a0_4
    a0_152 = a0_146*a0_4
    a0_153 = Rb*ca.cos(beta6)
    a0_154 = Rp*ca.cos(pi6) + q6x
    a0_155 = a0_154*a0_4
    a0_156 = a0_155*a0_2
    a0_157 = a0_14*q6z
    a0_158 = Rp*ca.sin(pi6) + q6y
    a0_159 = a0_158*a0_20
    a0_160 = 2*a0_156 + 2*a0_157 + 2*a0_159
    a0_161 = a0_0 - 2*a0_153 + a0_160 - 2*b6x
    a0_162 = Rb*ca.sin(beta6)
    a0_163 = a0_155*a0_8
    a0_164 = 2*a0_163
    a0_165 = a0_29*q6z
    a0_166 = a0_158*a0_32
    a0_167 = -2*a0_162 + a0_164 + 2*a0_165 + 2*a0_166 + a0_24 - 2*b6y
    a0_168 = 2*q6z
    a0_169 = a0_10*a0_154
    a0_170 = 2*a0_169
    a0_171 = 2*a0_158
    a0_172 = a0_168*a0_37 - a0_170 + a0_171*a0_41 + a0_35 - 2*b6z
    a0_173 = a0_158*a0_41 - a0_169 + a0_37*q6z - b6z + z
    a0_174 = -a0_153 + a0_156 + a0_157 + a0_159 - b6x + x
    a0_175 = -a0_162 + a0_163 + a0_165 + a0_166 - b6y + y
    a0_176 = a0_168*a0_4
    a0_177 = a0_171*a0_4
    a0_178 = 2*a0_4
    a0_179 = a0_178*a0_8
    a0_180 = a0_178*a0_2
    a0_181 = 2*a0_43
    a0_182 = 2*a0_12 + 2*a0_31
    a0_183 = -2*a0_17 + 2*a0_19
    a0_184 = -2*a0_18 + 2*a0_28
    a0_185 = 2*a0_13 + 2*a0_9
    a0_186 = 2*a0_73
    a0_187 = 2*a0_98
    a0_188 = 2*a0_123
    a0_189 = 2*a0_148
    a0_190 = 2*a0_173
    A0 = ca.vertcat(
        ca.horzcat(a0_23, a0_34, a0_42, a0_43*(2*a0_11*a0_16*a0_4 - a0_36*a0_41) + a0_45*(a0_14*a0_40 + a0_36*a0_44) + a0_47*(a0_29*a0_40 + a0_36*a0_46), a0_43*(-a0_36*a0_48 - a0_40*a0_49 - 2*a0_5) + a0_45*(a0_12*a0_50 + a0_18*a0_51 - a0_2*a0_39) + a0_47*(a0_17*a0_50 - a0_39*a0_8 + a0_51*a0_9), a0_22*a0_47 + a0_45*(-a0_27 + a0_36*a0_52 + a0_40*a0_46)),
        ca.horzcat(a0_61, a0_67, a0_72, a0_73*(2*a0_11*a0_4*a0_58 - a0_41*a0_68) + a0_74*(a0_14*a0_71 + a0_44*a0_68) + a0_75*(a0_29*a0_71 + a0_46*a0_68), a0_73*(-a0_48*a0_68 - a0_49*a0_71 - 2*a0_55) + a0_74*(a0_12*a0_76 + a0_18*a0_77 - a0_2*a0_70) + a0_75*(a0_17*a0_76 - a0_70*a0_8 + a0_77*a0_9), a0_60*a0_75 + a0_74*(a0_46*a0_71 + a0_52*a0_68 - a0_64)),
        ca.horzcat(a0_86, a0_92, a0_97, a0_100*(a0_29*a0_96 + a0_46*a0_93) + a0_98*(2*a0_11*a0_4*a0_83 - a0_41*a0_93) + a0_99*(a0_14*a0_96 + a0_44*a0_93), a0_100*(a0_101*a0_17 + a0_102*a0_9 - a0_8*a0_95) + a0_98*(-a0_48*a0_93 - a0_49*a0_96 - 2*a0_80) + a0_99*(a0_101*a0_12 + a0_102*a0_18 - a0_2*a0_95), a0_100*a0_85 + a0_99*(a0_46*a0_96 + a0_52*a0_93 - a0_89)),
        ca.horzcat(a0_111, a0_117, a0_122, a0_123*(2*a0_108*a0_11*a0_4 - a0_118*a0_41) + a0_124*(a0_118*a0_44 + a0_121*a0_14) + a0_125*(a0_118*a0_46 + a0_121*a0_29), a0_123*(-2*a0_105 - a0_118*a0_48 - a0_121*a0_49) + a0_124*(a0_12*a0_126 - a0_120*a0_2 + a0_127*a0_18) + a0_125*(-a0_120*a0_8 + a0_126*a0_17 + a0_127*a0_9), a0_110*a0_125 + a0_124*(-a0_114 + a0_118*a0_52 + a0_121*a0_46)),
        ca.horzcat(a0_136, a0_142, a0_147, a0_148*(2*a0_11*a0_133*a0_4 - a0_143*a0_41) + a0_149*(a0_14*a0_146 + a0_143*a0_44) + a0_150*(a0_143*a0_46 + a0_146*a0_29), a0_148*(-2*a0_130 - a0_143*a0_48 - a0_146*a0_49) + a0_149*(a0_12*a0_151 - a0_145*a0_2 + a0_152*a0_18) + a0_150*(-a0_145*a0_8 + a0_151*a0_17 + a0_152*a0_9), a0_135*a0_150 + a0_149*(-a0_139 + a0_143*a0_52 + a0_146*a0_46)),
        ca.horzcat(a0_161, a0_167, a0_172, a0_173*(2*a0_11*a0_158*a0_4 - a0_168*a0_41) + a0_174*(a0_14*a0_171 + a0_168*a0_44) + a0_175*(a0_168*a0_46 + a0_171*a0_29), a0_173*(-2*a0_155 - a0_168*a0_48 - a0_171*a0_49) + a0_174*(a0_12*a0_176 - a0_170*a0_2 + a0_177*a0_18) + a0_175*(a0_17*a0_176 - a0_170*a0_8 + a0_177*a0_9), a0_160*a0_175 + a0_174*(-a0_164 + a0_168*a0_52 + a0_171*a0_46)),
    )
    B0 = ca.vertcat(
        ca.horzcat(2*L1, 0, 0, 0, 0, 0, a0_23, a0_34, a0_42, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_43 - a0_179*a0_47 - a0_180*a0_45, -a0_181*a0_41 - a0_182*a0_47 - a0_183*a0_45, -a0_181*a0_37 - a0_184*a0_47 - a0_185*a0_45, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 2*L2, 0, 0, 0, 0, 0, 0, 0, a0_61, a0_67, a0_72, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_73 - a0_179*a0_75 - a0_180*a0_74, -a0_182*a0_75 - a0_183*a0_74 - a0_186*a0_41, -a0_184*a0_75 - a0_185*a0_74 - a0_186*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 2*L3, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_86, a0_92, a0_97, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_98 - a0_100*a0_179 - a0_180*a0_99, -a0_100*a0_182 - a0_183*a0_99 - a0_187*a0_41, -a0_100*a0_184 - a0_185*a0_99 - a0_187*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 2*L4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_111, a0_117, a0_122, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_123 - a0_124*a0_180 - a0_125*a0_179, -a0_124*a0_183 - a0_125*a0_182 - a0_188*a0_41, -a0_124*a0_185 - a0_125*a0_184 - a0_188*a0_37, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 2*L5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_136, a0_142, a0_147, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_148 - a0_149*a0_180 - a0_150*a0_179, -a0_149*a0_183 - a0_150*a0_182 - a0_189*a0_41, -a0_149*a0_185 - a0_150*a0_184 - a0_189*a0_37, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 2*L6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_161, a0_167, a0_172, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_173 - a0_174*a0_180 - a0_175*a0_179, -a0_174*a0_183 - a0_175*a0_182 - a0_190*a0_41, -a0_174*a0_185 - a0_175*a0_184 - a0_190*a0_37),
    )
    X0 = ca.solve(A0, B0)
    J_0_0 = X0[0, 0]
    J_0_1 = X0[0, 1]
    J_0_2 = X0[0, 2]
    J_0_3 = X0[0, 3]
    J_0_4 = X0[0, 4]
    J_0_5 = X0[0, 5]
    J_0_6 = X0[0, 6]
    J_0_7 = X0[0, 7]
    J_0_8 = X0[0, 8]
    J_0_9 = X0[0, 9]
    J_0_10 = X0[0, 10]
    J_0_11 = X0[0, 11]
    J_0_12 = X0[0, 12]
    J_0_13 = X0[0, 13]
    J_0_14 = X0[0, 14]
    J_0_15 = X0[0, 15]
    J_0_16 = X0[0, 16]
    J_0_17 = X0[0, 17]
    J_0_18 = X0[0, 18]
    J_0_19 = X0[0, 19]
    J_0_20 = X0[0, 20]
    J_0_21 = X0[0, 21]
    J_0_22 = X0[0, 22]
    J_0_23 = X0[0, 23]
    J_0_24 = X0[0, 24]
    J_0_25 = X0[0, 25]
    J_0_26 = X0[0, 26]
    J_0_27 = X0[0, 27]
    J_0_28 = X0[0, 28]
    J_0_29 = X0[0, 29]
    J_0_30 = X0[0, 30]
    J_0_31 = X0[0, 31]
    J_0_32 = X0[0, 32]
    J_0_33 = X0[0, 33]
    J_0_34 = X0[0, 34]
    J_0_35 = X0[0, 35]
    J_0_36 = X0[0, 36]
    J_0_37 = X0[0, 37]
    J_0_38 = X0[0, 38]
    J_0_39 = X0[0, 39]
    J_0_40 = X0[0, 40]
    J_0_41 = X0[0, 41]
    J_1_0 = X0[1, 0]
    J_1_1 = X0[1, 1]
    J_1_2 = X0[1, 2]
    J_1_3 = X0[1, 3]
    J_1_4 = X0[1, 4]
    J_1_5 = X0[1, 5]
    J_1_6 = X0[1, 6]
    J_1_7 = X0[1, 7]
    J_1_8 = X0[1, 8]
    J_1_9 = X0[1, 9]
    J_1_10 = X0[1, 10]
    J_1_11 = X0[1, 11]
    J_1_12 = X0[1, 12]
    J_1_13 = X0[1, 13]
    J_1_14 = X0[1, 14]
    J_1_15 = X0[1, 15]
    J_1_16 = X0[1, 16]
    J_1_17 = X0[1, 17]
    J_1_18 = X0[1, 18]
    J_1_19 = X0[1, 19]
    J_1_20 = X0[1, 20]
    J_1_21 = X0[1, 21]
    J_1_22 = X0[1, 22]
    J_1_23 = X0[1, 23]
    J_1_24 = X0[1, 24]
    J_1_25 = X0[1, 25]
    J_1_26 = X0[1, 26]
    J_1_27 = X0[1, 27]
    J_1_28 = X0[1, 28]
    J_1_29 = X0[1, 29]
    J_1_30 = X0[1, 30]
    J_1_31 = X0[1, 31]
    J_1_32 = X0[1, 32]
    J_1_33 = X0[1, 33]
    J_1_34 = X0[1, 34]
    J_1_35 = X0[1, 35]
    J_1_36 = X0[1, 36]
    J_1_37 = X0[1, 37]
    J_1_38 = X0[1, 38]
    J_1_39 = X0[1, 39]
    J_1_40 = X0[1, 40]
    J_1_41 = X0[1, 41]
    J_2_0 = X0[2, 0]
    J_2_1 = X0[2, 1]
    J_2_2 = X0[2, 2]
    J_2_3 = X0[2, 3]
    J_2_4 = X0[2, 4]
    J_2_5 = X0[2, 5]
    J_2_6 = X0[2, 6]
    J_2_7 = X0[2, 7]
    J_2_8 = X0[2, 8]
    J_2_9 = X0[2, 9]
    J_2_10 = X0[2, 10]
    J_2_11 = X0[2, 11]
    J_2_12 = X0[2, 12]
    J_2_13 = X0[2, 13]
    J_2_14 = X0[2, 14]
    J_2_15 = X0[2, 15]
    J_2_16 = X0[2, 16]
    J_2_17 = X0[2, 17]
    J_2_18 = X0[2, 18]
    J_2_19 = X0[2, 19]
    J_2_20 = X0[2, 20]
    J_2_21 = X0[2, 21]
    J_2_22 = X0[2, 22]
    J_2_23 = X0[2, 23]
    J_2_24 = X0[2, 24]
    J_2_25 = X0[2, 25]
    J_2_26 = X0[2, 26]
    J_2_27 = X0[2, 27]
    J_2_28 = X0[2, 28]
    J_2_29 = X0[2, 29]
    J_2_30 = X0[2, 30]
    J_2_31 = X0[2, 31]
    J_2_32 = X0[2, 32]
    J_2_33 = X0[2, 33]
    J_2_34 = X0[2, 34]
    J_2_35 = X0[2, 35]
    J_2_36 = X0[2, 36]
    J_2_37 = X0[2, 37]
    J_2_38 = X0[2, 38]
    J_2_39 = X0[2, 39]
    J_2_40 = X0[2, 40]
    J_2_41 = X0[2, 41]
    J_3_0 = X0[3, 0]
    J_3_1 = X0[3, 1]
    J_3_2 = X0[3, 2]
    J_3_3 = X0[3, 3]
    J_3_4 = X0[3, 4]
    J_3_5 = X0[3, 5]
    J_3_6 = X0[3, 6]
    J_3_7 = X0[3, 7]
    J_3_8 = X0[3, 8]
    J_3_9 = X0[3, 9]
    J_3_10 = X0[3, 10]
    J_3_11 = X0[3, 11]
    J_3_12 = X0[3, 12]
    J_3_13 = X0[3, 13]
    J_3_14 = X0[3, 14]
    J_3_15 = X0[3, 15]
    J_3_16 = X0[3, 16]
    J_3_17 = X0[3, 17]
    J_3_18 = X0[3, 18]
    J_3_19 = X0[3, 19]
    J_3_20 = X0[3, 20]
    J_3_21 = X0[3, 21]
    J_3_22 = X0[3, 22]
    J_3_23 = X0[3, 23]
    J_3_24 = X0[3, 24]
    J_3_25 = X0[3, 25]
    J_3_26 = X0[3, 26]
    J_3_27 = X0[3, 27]
    J_3_28 = X0[3, 28]
    J_3_29 = X0[3, 29]
    J_3_30 = X0[3, 30]
    J_3_31 = X0[3, 31]
    J_3_32 = X0[3, 32]
    J_3_33 = X0[3, 33]
    J_3_34 = X0[3, 34]
    J_3_35 = X0[3, 35]
    J_3_36 = X0[3, 36]
    J_3_37 = X0[3, 37]
    J_3_38 = X0[3, 38]
    J_3_39 = X0[3, 39]
    J_3_40 = X0[3, 40]
    J_3_41 = X0[3, 41]
    J_4_0 = X0[4, 0]
    J_4_1 = X0[4, 1]
    J_4_2 = X0[4, 2]
    J_4_3 = X0[4, 3]
    J_4_4 = X0[4, 4]
    J_4_5 = X0[4, 5]
    J_4_6 = X0[4, 6]
    J_4_7 = X0[4, 7]
    J_4_8 = X0[4, 8]
    J_4_9 = X0[4, 9]
    J_4_10 = X0[4, 10]
    J_4_11 = X0[4, 11]
    J_4_12 = X0[4, 12]
    J_4_13 = X0[4, 13]
    J_4_14 = X0[4, 14]
    J_4_15 = X0[4, 15]
    J_4_16 = X0[4, 16]
    J_4_17 = X0[4, 17]
    J_4_18 = X0[4, 18]
    J_4_19 = X0[4, 19]
    J_4_20 = X0[4, 20]
    J_4_21 = X0[4, 21]
    J_4_22 = X0[4, 22]
    J_4_23 = X0[4, 23]
    J_4_24 = X0[4, 24]
    J_4_25 = X0[4, 25]
    J_4_26 = X0[4, 26]
    J_4_27 = X0[4, 27]
    J_4_28 = X0[4, 28]
    J_4_29 = X0[4, 29]
    J_4_30 = X0[4, 30]
    J_4_31 = X0[4, 31]
    J_4_32 = X0[4, 32]
    J_4_33 = X0[4, 33]
    J_4_34 = X0[4, 34]
    J_4_35 = X0[4, 35]
    J_4_36 = X0[4, 36]
    J_4_37 = X0[4, 37]
    J_4_38 = X0[4, 38]
    J_4_39 = X0[4, 39]
    J_4_40 = X0[4, 40]
    J_4_41 = X0[4, 41]
    J_5_0 = X0[5, 0]
    J_5_1 = X0[5, 1]
    J_5_2 = X0[5, 2]
    J_5_3 = X0[5, 3]
    J_5_4 = X0[5, 4]
    J_5_5 = X0[5, 5]
    J_5_6 = X0[5, 6]
    J_5_7 = X0[5, 7]
    J_5_8 = X0[5, 8]
    J_5_9 = X0[5, 9]
    J_5_10 = X0[5, 10]
    J_5_11 = X0[5, 11]
    J_5_12 = X0[5, 12]
    J_5_13 = X0[5, 13]
    J_5_14 = X0[5, 14]
    J_5_15 = X0[5, 15]
    J_5_16 = X0[5, 16]
    J_5_17 = X0[5, 17]
    J_5_18 = X0[5, 18]
    J_5_19 = X0[5, 19]
    J_5_20 = X0[5, 20]
    J_5_21 = X0[5, 21]
    J_5_22 = X0[5, 22]
    J_5_23 = X0[5, 23]
    J_5_24 = X0[5, 24]
    J_5_25 = X0[5, 25]
    J_5_26 = X0[5, 26]
    J_5_27 = X0[5, 27]
    J_5_28 = X0[5, 28]
    J_5_29 = X0[5, 29]
    J_5_30 = X0[5, 30]
    J_5_31 = X0[5, 31]
    J_5_32 = X0[5, 32]
    J_5_33 = X0[5, 33]
    J_5_34 = X0[5, 34]
    J_5_35 = X0[5, 35]
    J_5_36 = X0[5, 36]
    J_5_37 = X0[5, 37]
    J_5_38 = X0[5, 38]
    J_5_39 = X0[5, 39]
    J_5_40 = X0[5, 40]
    J_5_41 = X0[5, 41]
    J = ca.vertcat(
        ca.horzcat(J_0_0, J_0_1, J_0_2, J_0_3, J_0_4, J_0_5),
        ca.horzcat(J_1_0, J_1_1, J_1_2, J_1_3, J_1_4, J_1_5),
        ca.horzcat(J_2_0, J_2_1, J_2_2, J_2_3, J_2_4, J_2_5),
        ca.horzcat(J_3_0, J_3_1, J_3_2, J_3_3, J_3_4, J_3_5),
        ca.horzcat(J_4_0, J_4_1, J_4_2, J_4_3, J_4_4, J_4_5),
        ca.horzcat(J_5_0, J_5_1, J_5_2, J_5_3, J_5_4, J_5_5),
    )
    return (J,)


def _measuring(P, g):
    """Nominal measuring-mechanism length |O2 - O1| and its unit vector."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    cx = g[52]
    cy = g[53]
    cz = g[54]
    dx = g[55]
    dy = g[56]
    dz = g[57]
    t0 = ca.sin(pitch)
    t1 = ca.sin(roll)
    t2 = ca.cos(pitch)
    t3 = ca.cos(roll)
    t4 = -cz - dx*t0 + dy*t1*t2 + dz*t2*t3 + z
    t5 = ca.cos(yaw)
    t6 = dx*t2
    t7 = ca.sin(yaw)
    t8 = t1*t7
    t9 = t3*t5
    t10 = t3*t7
    t11 = t1*t5
    t12 = -cx + dy*(t0*t11 - t10) + dz*(t0*t9 + t8) + t5*t6 + x
    t13 = -cy + dy*(t0*t8 + t9) + dz*(t0*t10 - t11) + t6*t7 + y
    t14 = ca.sqrt(t12**2 + t13**2 + t4**2)
    t15 = 1/t14
    lam = ca.vertcat(t14)
    lam_hat = ca.vertcat(t12*t15, t13*t15, t15*t4)
    return (lam, lam_hat,)


def _g_row(P, theta, g):
    """Identification row g_k = d rho / d(offsets as lengths, measuring errors) (paper Eq. 28: lam_hat^T [J, -I] for lambda = P - c - d)."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    L1 = theta[0]
    L2 = theta[1]
    L3 = theta[2]
    L4 = theta[3]
    L5 = theta[4]
    L6 = theta[5]
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    cx = g[52]
    cy = g[53]
    cz = g[54]
    dx = g[55]
    dy = g[56]
    dz = g[57]
    a0_0 = 2*x
    a0_1 = Rb*ca.cos(beta1)
    a0_2 = ca.cos(yaw)
    a0_3 = Rp*ca.cos(pi1) + q1x
    a0_4 = ca.cos(pitch)
    a0_5 = a0_3*a0_4
    a0_6 = a0_2*a0_5
    a0_7 = ca.sin(roll)
    a0_8 = ca.sin(yaw)
    a0_9 = a0_7*a0_8
    a0_10 = ca.sin(pitch)
    a0_11 = ca.cos(roll)
    a0_12 = a0_11*a0_2
    a0_13 = a0_10*a0_12
    a0_14 = a0_13 + a0_9
    a0_15 = a0_14*q1z
    a0_16 = Rp*ca.sin(pi1) + q1y
    a0_17 = a0_11*a0_8
    a0_18 = a0_2*a0_7
    a0_19 = a0_10*a0_18
    a0_20 = -a0_17 + a0_19
    a0_21 = a0_16*a0_20
    a0_22 = 2*a0_15 + 2*a0_21 + 2*a0_6
    a0_23 = a0_0 - 2*a0_1 + a0_22 - 2*b1x
    a0_24 = 2*y
    a0_25 = Rb*ca.sin(beta1)
    a0_26 = a0_5*a0_8
    a0_27 = 2*a0_26
    a0_28 = a0_10*a0_17
    a0_29 = -a0_18 + a0_28
    a0_30 = a0_29*q1z
    a0_31 = a0_10*a0_9
    a0_32 = a0_12 + a0_31
    a0_33 = a0_16*a0_32
    a0_34 = a0_24 - 2*a0_25 + a0_27 + 2*a0_30 + 2*a0_33 - 2*b1y
    a0_35 = 2*z
    a0_36 = 2*q1z
    a0_37 = a0_11*a0_4
    a0_38 = a0_10*a0_3
    a0_39 = 2*a0_38
    a0_40 = 2*a0_16
    a0_41 = a0_4*a0_7
    a0_42 = a0_35 + a0_36*a0_37 - a0_39 + a0_40*a0_41 - 2*b1z
    a0_43 = a0_16*a0_41 + a0_37*q1z - a0_38 - b1z + z
    a0_44 = -a0_20
    a0_45 = -a0_1 + a0_15 + a0_21 + a0_6 - b1x + x
    a0_46 = -a0_32
    a0_47 = -a0_25 + a0_26 + a0_30 + a0_33 - b1y + y
    a0_48 = a0_10*a0_11
    a0_49 = a0_10*a0_7
    a0_50 = a0_36*a0_4
    a0_51 = a0_4*a0_40
    a0_52 = -a0_29
    a0_53 = Rb*ca.cos(beta2)
    a0_54 = Rp*ca.cos(pi2) + q2x
    a0_55 = a0_4*a0_54
    a0_56 = a0_2*a0_55
    a0_57 = a0_14*q2z
    a0_58 = Rp*ca.sin(pi2) + q2y
    a0_59 = a0_20*a0_58
    a0_60 = 2*a0_56 + 2*a0_57 + 2*a0_59
    a0_61 = a0_0 - 2*a0_53 + a0_60 - 2*b2x
    a0_62 = Rb*ca.sin(beta2)
    a0_63 = a0_55*a0_8
    a0_64 = 2*a0_63
    a0_65 = a0_29*q2z
    a0_66 = a0_32*a0_58
    a0_67 = a0_24 - 2*a0_62 + a0_64 + 2*a0_65 + 2*a0_66 - 2*b2y
    a0_68 = 2*q2z
    a0_69 = a0_10*a0_54
    a0_70 = 2*a0_69
    a0_71 = 2*a0_58
    a0_72 = a0_35 + a0_37*a0_68 + a0_41*a0_71 - a0_70 - 2*b2z
    a0_73 = a0_37*q2z + a0_41*a0_58 - a0_69 - b2z + z
    a0_74 = -a0_53 + a0_56 + a0_57 + a0_59 - b2x + x
    a0_75 = -a0_62 + a0_63 + a0_65 + a0_66 - b2y + y
    a0_76 = a0_4*a0_68
    a0_77 = a0_4*a0_71
    a0_78 = Rb*ca.cos(beta3)
    a0_79 = Rp*ca.cos(pi3) + q3x
    a0_80 = a0_4*a0_79
    a0_81 = a0_2*a0_80
    a0_82 = a0_14*q3z
    a0_83 = Rp*ca.sin(pi3) + q3y
    a0_84 = a0_20*a0_83
    a0_85 = 2*a0_81 + 2*a0_82 + 2*a0_84
    a0_86 = a0_0 - 2*a0_78 + a0_85 - 2*b3x
    a0_87 = Rb*ca.sin(beta3)
    a0_88 = a0_8*a0_80
    a0_89 = 2*a0_88
    a0_90 = a0_29*q3z
    a0_91 = a0_32*a0_83
    a0_92 = a0_24 - 2*a0_87 + a0_89 + 2*a0_90 + 2*a0_91 - 2*b3y
    a0_93 = 2*q3z
    a0_94 = a0_10*a0_79
    a0_95 = 2*a0_94
    a0_96 = 2*a0_83
    a0_97 = a0_35 + a0_37*a0_93 + a0_41*a0_96 - a0_95 - 2*b3z
    a0_98 = a0_37*q3z + a0_41*a0_83 - a0_94 - b3z + z
    a0_99 = -a0_78 + a0_81 + a0_82 + a0_84 - b3x + x
    a0_100 = -a0_87 + a0_88 + a0_90 + a0_91 - b3y + y
    a0_101 = a0_4*a0_93
    a0_102 = a0_4*a0_96
    a0_103 = Rb*ca.cos(beta4)
    a0_104 = Rp*ca.cos(pi4) + q4x
    a0_105 = a0_104*a0_4
    a0_106 = a0_105*a0_2
    a0_107 = a0_14*q4z
    a0_108 = Rp*ca.sin(pi4) + q4y
    a0_109 = a0_108*a0_20
    a0_110 = 2*a0_106 + 2*a0_107 + 2*a0_109
    a0_111 = a0_0 - 2*a0_103 + a0_110 - 2*b4x
    a0_112 = Rb*ca.sin(beta4)
    a0_113 = a0_105*a0_8
    a0_114 = 2*a0_113
    a0_115 = a0_29*q4z
    a0_116 = a0_108*a0_32
    a0_117 = -2*a0_112 + a0_114 + 2*a0_115 + 2*a0_116 + a0_24 - 2*b4y
    a0_118 = 2*q4z
    a0_119 = a0_10*a0_104
    a0_120 = 2*a0_119
    a0_121 = 2*a0_108
    a0_122 = a0_118*a0_37 - a0_120 + a0_121*a0_41 + a0_35 - 2*b4z
    a0_123 = a0_108*a0_41 - a0_119 + a0_37*q4z - b4z + z
    a0_124 = -a0_103 + a0_106 + a0_107 + a0_109 - b4x + x
    a0_125 = -a0_112 + a0_113 + a0_115 + a0_116 - b4y + y
    a0_126 = a0_118*a0_4
    a0_127 = a0_121*a0_4
    a0_128 = Rb*ca.cos(beta5)
    a0_129 = Rp*ca.cos(pi5) + q5x
    a0_130 = a0_129*a0_4
    a0_131 = a0_130*a0_2
    a0_132 = a0_14*q5z
    a0_133 = Rp*ca.sin(pi5) + q5y
    a0_134 = a0_133*a0_20
    a0_135 = 2*a0_131 + 2*a0_132 + 2*a0_134
    a0_136 = a0_0 - 2*a0_128 + a0_135 - 2*b5x
    a0_137 = Rb*ca.sin(beta5)
    a0_138 = a0_130*a0_8
    a0_139 = 2*a0_138
    a0_140 = a0_29*q5z
    a0_141 = a0_133*a0_32
    a0_142 = -2*a0_137 + a0_139 + 2*a0_140 + 2*a0_141 + a0_24 - 2*b5y
    a0_143 = 2*q5z
    a0_144 = a0_10*a0_129
    a0_145 = 2*a0_144
    a0_146 = 2*a0_133
    a0_147 = a0_143*a0_37 - a0_145 + a0_146*a0_41 + a0_35 - 2*b5z
    a0_148 = a0_133*a0_41 - a0_144 + a0_37*q5z - b5z + z
    a0_149 = -a0_128 + a0_131 + a0_132 + a0_134 - b5x + x
    a0_150 = -a0_137 + a0_138 + a0_140 + a0_141 - b5y + y
    a0_151 = a0_143*a0_4
    a0_152 = a0_146*a0_4
    a0_153 = Rb*ca.cos(beta6)
    a0_154 = Rp*ca.cos(pi6) + q6x
    a0_155 = a0_154*a0_4
    a0_156 = a0_155*a0_2
    a0_157 = a0_14*q6z
    a0_158 = Rp*ca.sin(pi6) + q6y
    a0_159 = a0_158*a0_20
    a0_160 = 2*a0_156 + 2*a0_157 + 2*a0_159
    a0_161 = a0_0 - 2*a0_153 + a0_160 - 2*b6x
    a0_162 = Rb*ca.sin(beta6)
    a0_163 = a0_155*a0_8
    a0_164 = 2*a0_163
    a0_165 = a0_29*q6z
    a0_166 = a0_158*a0_32
    a0_167 = -2*a0_162 + a0_164 + 2*a0_165 + 2*a0_166 + a0_24 - 2*b6y
    a0_168 = 2*q6z
    a0_169 = a0_10*a0_154
    a0_170 = 2*a0_169
    a0_171 = 2*a0_158
    a0_172 = a0_168*a0_37 - a0_170 + a0_171*a0_41 + a0_35 - 2*b6z
    a0_173 = a0_158*a0_41 - a0_169 + a0_37*q6z - b6z + z
    a0_174 = -a0_153 + a0_156 + a0_157 + a0_159 - b6x + x
    a0_175 = -a0_162 + a0_163 + a0_165 + a0_166 - b6y + y
    a0_176 = a0_168*a0_4
    a0_177 = a0_171*a0_4
    a0_178 = 2*a0_4
    a0_179 = a0_178*a0_8
    a0_180 = a0_178*a0_2
    a0_181 = 2*a0_43
    a0_182 = 2*a0_12 + 2*a0_31
    a0_183 = -2*a0_17 + 2*a0_19
    a0_184 = -2*a0_18 + 2*a0_28
    a0_185 = 2*a0_13 + 2*a0_9
    a0_186 = 2*a0_73
    a0_187 = 2*a0_98
    a0_188 = 2*a0_123
    a0_189 = 2*a0_148
    a0_190 = 2*a0_173
    A0 = ca.vertcat(
        ca.horzcat(a0_23, a0_34, a0_42, a0_43*(2*a0_11*a0_16*a0_4 - a0_36*a0_41) + a0_45*(a0_14*a0_40 + a0_36*a0_44) + a0_47*(a0_29*a0_40 + a0_36*a0_46), a0_43*(-a0_36*a0_48 - a0_40*a0_49 - 2*a0_5) + a0_45*(a0_12*a0_50 + a0_18*a0_51 - a0_2*a0_39) + a0_47*(a0_17*a0_50 - a0_39*a0_8 + a0_51*a0_9), a0_22*a0_47 + a0_45*(-a0_27 + a0_36*a0_52 + a0_40*a0_46)),
        ca.horzcat(a0_61, a0_67, a0_72, a0_73*(2*a0_11*a0_4*a0_58 - a0_41*a0_68) + a0_74*(a0_14*a0_71 + a0_44*a0_68) + a0_75*(a0_29*a0_71 + a0_46*a0_68), a0_73*(-a0_48*a0_68 - a0_49*a0_71 - 2*a0_55) + a0_74*(a0_12*a0_76 + a0_18*a0_77 - a0_2*a0_70) + a0_75*(a0_17*a0_76 - a0_70*a0_8 + a0_77*a0_9), a0_60*a0_75 + a0_74*(a0_46*a0_71 + a0_52*a0_68 - a0_64)),
        ca.horzcat(a0_86, a0_92, a0_97, a0_100*(a0_29*a0_96 + a0_46*a0_93) + a0_98*(2*a0_11*a0_4*a0_83 - a0_41*a0_93) + a0_99*(a0_14*a0_96 + a0_44*a0_93), a0_100*(a0_101*a0_17 + a0_102*a0_9 - a0_8*a0_95) + a0_98*(-a0_48*a0_93 - a0_49*a0_96 - 2*a0_80) + a0_99*(a0_101*a0_12 + a0_102*a0_18 - a0_2*a0_95), a0_100*a0_85 + a0_99*(a0_46*a0_96 + a0_52*a0_93 - a0_89)),
        ca.horzcat(a0_111, a0_117, a0_122, a0_123*(2*a0_108*a0_11*a0_4 - a0_118*a0_41) + a0_124*(a0_118*a0_44 + a0_121*a0_14) + a0_125*(a0_118*a0_46 + a0_121*a0_29), a0_123*(-2*a0_105 - a0_118*a0_48 - a0_121*a0_49) + a0_124*(a0_12*a0_126 - a0_120*a0_2 + a0_127*a0_18) + a0_125*(-a0_120*a0_8 + a0_126*a0_17 + a0_127*a0_9), a0_110*a0_125 + a0_124*(-a0_114 + a0_118*a0_52 + a0_121*a0_46)),
        ca.horzcat(a0_136, a0_142, a0_147, a0_148*(2*a0_11*a0_133*a0_4 - a0_143*a0_41) + a0_149*(a0_14*a0_146 + a0_143*a0_44) + a0_150*(a0_143*a0_46 + a0_146*a0_29), a0_148*(-2*a0_130 - a0_143*a0_48 - a0_146*a0_49) + a0_149*(a0_12*a0_151 - a0_145*a0_2 + a0_152*a0_18) + a0_150*(-a0_145*a0_8 + a0_151*a0_17 + a0_152*a0_9), a0_135*a0_150 + a0_149*(-a0_139 + a0_143*a0_52 + a0_146*a0_46)),
        ca.horzcat(a0_161, a0_167, a0_172, a0_173*(2*a0_11*a0_158*a0_4 - a0_168*a0_41) + a0_174*(a0_14*a0_171 + a0_168*a0_44) + a0_175*(a0_168*a0_46 + a0_171*a0_29), a0_173*(-2*a0_155 - a0_168*a0_48 - a0_171*a0_49) + a0_174*(a0_12*a0_176 - a0_170*a0_2 + a0_177*a0_18) + a0_175*(a0_17*a0_176 - a0_170*a0_8 + a0_177*a0_9), a0_160*a0_175 + a0_174*(-a0_164 + a0_168*a0_52 + a0_171*a0_46)),
    )
    B0 = ca.vertcat(
        ca.horzcat(2*L1, 0, 0, 0, 0, 0, a0_23, a0_34, a0_42, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_43 - a0_179*a0_47 - a0_180*a0_45, -a0_181*a0_41 - a0_182*a0_47 - a0_183*a0_45, -a0_181*a0_37 - a0_184*a0_47 - a0_185*a0_45, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 2*L2, 0, 0, 0, 0, 0, 0, 0, a0_61, a0_67, a0_72, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_73 - a0_179*a0_75 - a0_180*a0_74, -a0_182*a0_75 - a0_183*a0_74 - a0_186*a0_41, -a0_184*a0_75 - a0_185*a0_74 - a0_186*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 2*L3, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_86, a0_92, a0_97, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_98 - a0_100*a0_179 - a0_180*a0_99, -a0_100*a0_182 - a0_183*a0_99 - a0_187*a0_41, -a0_100*a0_184 - a0_185*a0_99 - a0_187*a0_37, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 2*L4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_111, a0_117, a0_122, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_123 - a0_124*a0_180 - a0_125*a0_179, -a0_124*a0_183 - a0_125*a0_182 - a0_188*a0_41, -a0_124*a0_185 - a0_125*a0_184 - a0_188*a0_37, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 2*L5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_136, a0_142, a0_147, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_148 - a0_149*a0_180 - a0_150*a0_179, -a0_149*a0_183 - a0_150*a0_182 - a0_189*a0_41, -a0_149*a0_185 - a0_150*a0_184 - a0_189*a0_37, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 2*L6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, a0_161, a0_167, a0_172, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2*a0_10*a0_173 - a0_174*a0_180 - a0_175*a0_179, -a0_174*a0_183 - a0_175*a0_182 - a0_190*a0_41, -a0_174*a0_185 - a0_175*a0_184 - a0_190*a0_37),
    )
    X0 = ca.solve(A0, B0)
    J_0_0 = X0[0, 0]
    J_0_1 = X0[0, 1]
    J_0_2 = X0[0, 2]
    J_0_3 = X0[0, 3]
    J_0_4 = X0[0, 4]
    J_0_5 = X0[0, 5]
    J_0_6 = X0[0, 6]
    J_0_7 = X0[0, 7]
    J_0_8 = X0[0, 8]
    J_0_9 = X0[0, 9]
    J_0_10 = X0[0, 10]
    J_0_11 = X0[0, 11]
    J_0_12 = X0[0, 12]
    J_0_13 = X0[0, 13]
    J_0_14 = X0[0, 14]
    J_0_15 = X0[0, 15]
    J_0_16 = X0[0, 16]
    J_0_17 = X0[0, 17]
    J_0_18 = X0[0, 18]
    J_0_19 = X0[0, 19]
    J_0_20 = X0[0, 20]
    J_0_21 = X0[0, 21]
    J_0_22 = X0[0, 22]
    J_0_23 = X0[0, 23]
    J_0_24 = X0[0, 24]
    J_0_25 = X0[0, 25]
    J_0_26 = X0[0, 26]
    J_0_27 = X0[0, 27]
    J_0_28 = X0[0, 28]
    J_0_29 = X0[0, 29]
    J_0_30 = X0[0, 30]
    J_0_31 = X0[0, 31]
    J_0_32 = X0[0, 32]
    J_0_33 = X0[0, 33]
    J_0_34 = X0[0, 34]
    J_0_35 = X0[0, 35]
    J_0_36 = X0[0, 36]
    J_0_37 = X0[0, 37]
    J_0_38 = X0[0, 38]
    J_0_39 = X0[0, 39]
    J_0_40 = X0[0, 40]
    J_0_41 = X0[0, 41]
    J_1_0 = X0[1, 0]
    J_1_1 = X0[1, 1]
    J_1_2 = X0[1, 2]
    J_1_3 = X0[1, 3]
    J_1_4 = X0[1, 4]
    J_1_5 = X0[1, 5]
    J_1_6 = X0[1, 6]
    J_1_7 = X0[1, 7]
    J_1_8 = X0[1, 8]
    J_1_9 = X0[1, 9]
    J_1_10 = X0[1, 10]
    J_1_11 = X0[1, 11]
    J_1_12 = X0[1, 12]
    J_1_13 = X0[1, 13]
    J_1_14 = X0[1, 14]
    J_1_15 = X0[1, 15]
    J_1_16 = X0[1, 16]
    J_1_17 = X0[1, 17]
    J_1_18 = X0[1, 18]
    J_1_19 = X0[1, 19]
    J_1_20 = X0[1, 20]
    J_1_21 = X0[1, 21]
    J_1_22 = X0[1, 22]
    J_1_23 = X0[1, 23]
    J_1_24 = X0[1, 24]
    J_1_25 = X0[1, 25]
    J_1_26 = X0[1, 26]
    J_1_27 = X0[1, 27]
    J_1_28 = X0[1, 28]
    J_1_29 = X0[1, 29]
    J_1_30 = X0[1, 30]
    J_1_31 = X0[1, 31]
    J_1_32 = X0[1, 32]
    J_1_33 = X0[1, 33]
    J_1_34 = X0[1, 34]
    J_1_35 = X0[1, 35]
    J_1_36 = X0[1, 36]
    J_1_37 = X0[1, 37]
    J_1_38 = X0[1, 38]
    J_1_39 = X0[1, 39]
    J_1_40 = X0[1, 40]
    J_1_41 = X0[1, 41]
    J_2_0 = X0[2, 0]
    J_2_1 = X0[2, 1]
    J_2_2 = X0[2, 2]
    J_2_3 = X0[2, 3]
    J_2_4 = X0[2, 4]
    J_2_5 = X0[2, 5]
    J_2_6 = X0[2, 6]
    J_2_7 = X0[2, 7]
    J_2_8 = X0[2, 8]
    J_2_9 = X0[2, 9]
    J_2_10 = X0[2, 10]
    J_2_11 = X0[2, 11]
    J_2_12 = X0[2, 12]
    J_2_13 = X0[2, 13]
    J_2_14 = X0[2, 14]
    J_2_15 = X0[2, 15]
    J_2_16 = X0[2, 16]
    J_2_17 = X0[2, 17]
    J_2_18 = X0[2, 18]
    J_2_19 = X0[2, 19]
    J_2_20 = X0[2, 20]
    J_2_21 = X0[2, 21]
    J_2_22 = X0[2, 22]
    J_2_23 = X0[2, 23]
    J_2_24 = X0[2, 24]
    J_2_25 = X0[2, 25]
    J_2_26 = X0[2, 26]
    J_2_27 = X0[2, 27]
    J_2_28 = X0[2, 28]
    J_2_29 = X0[2, 29]
    J_2_30 = X0[2, 30]
    J_2_31 = X0[2, 31]
    J_2_32 = X0[2, 32]
    J_2_33 = X0[2, 33]
    J_2_34 = X0[2, 34]
    J_2_35 = X0[2, 35]
    J_2_36 = X0[2, 36]
    J_2_37 = X0[2, 37]
    J_2_38 = X0[2, 38]
    J_2_39 = X0[2, 39]
    J_2_40 = X0[2, 40]
    J_2_41 = X0[2, 41]
    J_3_0 = X0[3, 0]
    J_3_1 = X0[3, 1]
    J_3_2 = X0[3, 2]
    J_3_3 = X0[3, 3]
    J_3_4 = X0[3, 4]
    J_3_5 = X0[3, 5]
    J_3_6 = X0[3, 6]
    J_3_7 = X0[3, 7]
    J_3_8 = X0[3, 8]
    J_3_9 = X0[3, 9]
    J_3_10 = X0[3, 10]
    J_3_11 = X0[3, 11]
    J_3_12 = X0[3, 12]
    J_3_13 = X0[3, 13]
    J_3_14 = X0[3, 14]
    J_3_15 = X0[3, 15]
    J_3_16 = X0[3, 16]
    J_3_17 = X0[3, 17]
    J_3_18 = X0[3, 18]
    J_3_19 = X0[3, 19]
    J_3_20 = X0[3, 20]
    J_3_21 = X0[3, 21]
    J_3_22 = X0[3, 22]
    J_3_23 = X0[3, 23]
    J_3_24 = X0[3, 24]
    J_3_25 = X0[3, 25]
    J_3_26 = X0[3, 26]
    J_3_27 = X0[3, 27]
    J_3_28 = X0[3, 28]
    J_3_29 = X0[3, 29]
    J_3_30 = X0[3, 30]
    J_3_31 = X0[3, 31]
    J_3_32 = X0[3, 32]
    J_3_33 = X0[3, 33]
    J_3_34 = X0[3, 34]
    J_3_35 = X0[3, 35]
    J_3_36 = X0[3, 36]
    J_3_37 = X0[3, 37]
    J_3_38 = X0[3, 38]
    J_3_39 = X0[3, 39]
    J_3_40 = X0[3, 40]
    J_3_41 = X0[3, 41]
    J_4_0 = X0[4, 0]
    J_4_1 = X0[4, 1]
    J_4_2 = X0[4, 2]
    J_4_3 = X0[4, 3]
    J_4_4 = X0[4, 4]
    J_4_5 = X0[4, 5]
    J_4_6 = X0[4, 6]
    J_4_7 = X0[4, 7]
    J_4_8 = X0[4, 8]
    J_4_9 = X0[4, 9]
    J_4_10 = X0[4, 10]
    J_4_11 = X0[4, 11]
    J_4_12 = X0[4, 12]
    J_4_13 = X0[4, 13]
    J_4_14 = X0[4, 14]
    J_4_15 = X0[4, 15]
    J_4_16 = X0[4, 16]
    J_4_17 = X0[4, 17]
    J_4_18 = X0[4, 18]
    J_4_19 = X0[4, 19]
    J_4_20 = X0[4, 20]
    J_4_21 = X0[4, 21]
    J_4_22 = X0[4, 22]
    J_4_23 = X0[4, 23]
    J_4_24 = X0[4, 24]
    J_4_25 = X0[4, 25]
    J_4_26 = X0[4, 26]
    J_4_27 = X0[4, 27]
    J_4_28 = X0[4, 28]
    J_4_29 = X0[4, 29]
    J_4_30 = X0[4, 30]
    J_4_31 = X0[4, 31]
    J_4_32 = X0[4, 32]
    J_4_33 = X0[4, 33]
    J_4_34 = X0[4, 34]
    J_4_35 = X0[4, 35]
    J_4_36 = X0[4, 36]
    J_4_37 = X0[4, 37]
    J_4_38 = X0[4, 38]
    J_4_39 = X0[4, 39]
    J_4_40 = X0[4, 40]
    J_4_41 = X0[4, 41]
    J_5_0 = X0[5, 0]
    J_5_1 = X0[5, 1]
    J_5_2 = X0[5, 2]
    J_5_3 = X0[5, 3]
    J_5_4 = X0[5, 4]
    J_5_5 = X0[5, 5]
    J_5_6 = X0[5, 6]
    J_5_7 = X0[5, 7]
    J_5_8 = X0[5, 8]
    J_5_9 = X0[5, 9]
    J_5_10 = X0[5, 10]
    J_5_11 = X0[5, 11]
    J_5_12 = X0[5, 12]
    J_5_13 = X0[5, 13]
    J_5_14 = X0[5, 14]
    J_5_15 = X0[5, 15]
    J_5_16 = X0[5, 16]
    J_5_17 = X0[5, 17]
    J_5_18 = X0[5, 18]
    J_5_19 = X0[5, 19]
    J_5_20 = X0[5, 20]
    J_5_21 = X0[5, 21]
    J_5_22 = X0[5, 22]
    J_5_23 = X0[5, 23]
    J_5_24 = X0[5, 24]
    J_5_25 = X0[5, 25]
    J_5_26 = X0[5, 26]
    J_5_27 = X0[5, 27]
    J_5_28 = X0[5, 28]
    J_5_29 = X0[5, 29]
    J_5_30 = X0[5, 30]
    J_5_31 = X0[5, 31]
    J_5_32 = X0[5, 32]
    J_5_33 = X0[5, 33]
    J_5_34 = X0[5, 34]
    J_5_35 = X0[5, 35]
    J_5_36 = X0[5, 36]
    J_5_37 = X0[5, 37]
    J_5_38 = X0[5, 38]
    J_5_39 = X0[5, 39]
    J_5_40 = X0[5, 40]
    J_5_41 = X0[5, 41]
    t0 = ca.cos(roll)
    t1 = ca.cos(pitch)
    t2 = dy*t1
    t3 = ca.sin(roll)
    t4 = dz*t1
    t5 = t0*t2 - t3*t4
    t6 = dx*t1
    t7 = ca.sin(pitch)
    t8 = -dy*t3*t7 - dz*t0*t7 - t6
    t9 = dx*t7
    t10 = -cz + t0*t4 + t2*t3 - t9 + z
    t11 = ca.cos(yaw)
    t12 = ca.sin(yaw)
    t13 = t12*t3
    t14 = t0*t11
    t15 = t13 + t14*t7
    t16 = t0*t12
    t17 = t11*t3
    t18 = -t16 + t17*t7
    t19 = dy*t18 + dz*t15 + t11*t6
    t20 = -cx + t19 + x
    t21 = t12*t6
    t22 = t13*t7 + t14
    t23 = t16*t7 - t17
    t24 = -cy + dy*t22 + dz*t23 + t21 + y
    t25 = 1/ca.sqrt(t10**2 + t20**2 + t24**2)
    t26 = t10*t25
    t27 = -t12*t9 + t13*t2 + t16*t4
    t28 = -t22
    t29 = dy*t23 + dz*t28
    t30 = t24*t25
    t31 = -t11*t9 + t14*t4 + t17*t2
    t32 = dy*t15 - dz*t18
    t33 = dy*t28 - dz*t23 - t21
    t34 = t20*t25
    t35 = t1*t26
    row = ca.vertcat(
        ca.horzcat(t26*(J_2_0 + J_3_0*t5 + J_4_0*t8) + t30*(J_1_0 + J_3_0*t29 + J_4_0*t27 + J_5_0*t19) + t34*(J_0_0 + J_3_0*t32 + J_4_0*t31 + J_5_0*t33), t26*(J_2_1 + J_3_1*t5 + J_4_1*t8) + t30*(J_1_1 + J_3_1*t29 + J_4_1*t27 + J_5_1*t19) + t34*(J_0_1 + J_3_1*t32 + J_4_1*t31 + J_5_1*t33), t26*(J_2_2 + J_3_2*t5 + J_4_2*t8) + t30*(J_1_2 + J_3_2*t29 + J_4_2*t27 + J_5_2*t19) + t34*(J_0_2 + J_3_2*t32 + J_4_2*t31 + J_5_2*t33), t26*(J_2_3 + J_3_3*t5 + J_4_3*t8) + t30*(J_1_3 + J_3_3*t29 + J_4_3*t27 + J_5_3*t19) + t34*(J_0_3 + J_3_3*t32 + J_4_3*t31 + J_5_3*t33), t26*(J_2_4 + J_3_4*t5 + J_4_4*t8) + t30*(J_1_4 + J_3_4*t29 + J_4_4*t27 + J_5_4*t19) + t34*(J_0_4 + J_3_4*t32 + J_4_4*t31 + J_5_4*t33), t26*(J_2_5 + J_3_5*t5 + J_4_5*t8) + t30*(J_1_5 + J_3_5*t29 + J_4_5*t27 + J_5_5*t19) + t34*(J_0_5 + J_3_5*t32 + J_4_5*t31 + J_5_5*t33), -t34, -t30, -t26, t1*t11*t34 + t1*t12*t30 - t26*t7, t18*t34 + t22*t30 + t3*t35, t0*t35 + t15*t34 + t23*t30),
    )
    return (row,)


def _distance(theta_cmd, g, err):
    """Exact distance O1'O2' for commanded joints, nominal geometry and source errors. (fk of the actual joints and geometry, then |measuring|)."""
    g_act = [g[k] for k in range(g.numel())]
    g_act[16] = g_act[16] + err[6]
    g_act[17] = g_act[17] + err[7]
    g_act[18] = g_act[18] + err[8]
    g_act[19] = g_act[19] + err[9]
    g_act[20] = g_act[20] + err[10]
    g_act[21] = g_act[21] + err[11]
    g_act[22] = g_act[22] + err[12]
    g_act[23] = g_act[23] + err[13]
    g_act[24] = g_act[24] + err[14]
    g_act[25] = g_act[25] + err[15]
    g_act[26] = g_act[26] + err[16]
    g_act[27] = g_act[27] + err[17]
    g_act[28] = g_act[28] + err[18]
    g_act[29] = g_act[29] + err[19]
    g_act[30] = g_act[30] + err[20]
    g_act[31] = g_act[31] + err[21]
    g_act[32] = g_act[32] + err[22]
    g_act[33] = g_act[33] + err[23]
    g_act[34] = g_act[34] + err[24]
    g_act[35] = g_act[35] + err[25]
    g_act[36] = g_act[36] + err[26]
    g_act[37] = g_act[37] + err[27]
    g_act[38] = g_act[38] + err[28]
    g_act[39] = g_act[39] + err[29]
    g_act[40] = g_act[40] + err[30]
    g_act[41] = g_act[41] + err[31]
    g_act[42] = g_act[42] + err[32]
    g_act[43] = g_act[43] + err[33]
    g_act[44] = g_act[44] + err[34]
    g_act[45] = g_act[45] + err[35]
    g_act[46] = g_act[46] + err[36]
    g_act[47] = g_act[47] + err[37]
    g_act[48] = g_act[48] + err[38]
    g_act[49] = g_act[49] + err[39]
    g_act[50] = g_act[50] + err[40]
    g_act[51] = g_act[51] + err[41]
    g_act[52] = g_act[52] + err[42]
    g_act[53] = g_act[53] + err[43]
    g_act[54] = g_act[54] + err[44]
    g_act[55] = g_act[55] + err[45]
    g_act[56] = g_act[56] + err[46]
    g_act[57] = g_act[57] + err[47]
    g_act = ca.vertcat(*g_act)
    theta = ca.vertcat(theta_cmd[0] + err[0], theta_cmd[1] + err[1], theta_cmd[2] + err[2], theta_cmd[3] + err[3], theta_cmd[4] + err[4], theta_cmd[5] + err[5])
    P = _fk(theta, g_act)[0]
    return (_measuring(P, g_act)[0],)


def _gauge(g):
    """Gauge motions (columns): source-error directions no distance change can see."""
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    cx = g[52]
    cy = g[53]
    cz = g[54]
    dx = g[55]
    dy = g[56]
    dz = g[57]
    t0 = Rb*ca.sin(beta1) + b1y
    t1 = Rb*ca.cos(beta1) + b1x
    t2 = Rb*ca.sin(beta2) + b2y
    t3 = Rb*ca.cos(beta2) + b2x
    t4 = Rb*ca.sin(beta3) + b3y
    t5 = Rb*ca.cos(beta3) + b3x
    t6 = Rb*ca.sin(beta4) + b4y
    t7 = Rb*ca.cos(beta4) + b4x
    t8 = Rb*ca.sin(beta5) + b5y
    t9 = Rb*ca.cos(beta5) + b5x
    t10 = Rb*ca.sin(beta6) + b6y
    t11 = Rb*ca.cos(beta6) + b6x
    t12 = Rp*ca.sin(pi1) + q1y
    t13 = Rp*ca.cos(pi1) + q1x
    t14 = Rp*ca.sin(pi2) + q2y
    t15 = Rp*ca.cos(pi2) + q2x
    t16 = Rp*ca.sin(pi3) + q3y
    t17 = Rp*ca.cos(pi3) + q3x
    t18 = Rp*ca.sin(pi4) + q4y
    t19 = Rp*ca.cos(pi4) + q4x
    t20 = Rp*ca.sin(pi5) + q5y
    t21 = Rp*ca.cos(pi5) + q5x
    t22 = Rp*ca.sin(pi6) + q6y
    t23 = Rp*ca.cos(pi6) + q6x
    Z = ca.vertcat(
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b1z, -t0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b1z, 0, t1, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t0, -t1, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b2z, -t2, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b2z, 0, t3, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t2, -t3, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b3z, -t4, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b3z, 0, t5, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t4, -t5, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b4z, -t6, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b4z, 0, t7, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t6, -t7, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b5z, -t8, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b5z, 0, t9, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t8, -t9, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(1, 0, 0, 0, b6z, -t10, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -b6z, 0, t11, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, t10, -t11, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q1z, -t12),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q1z, 0, t13),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t12, -t13, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q2z, -t14),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q2z, 0, t15),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t14, -t15, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q3z, -t16),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q3z, 0, t17),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t16, -t17, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q4z, -t18),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q4z, 0, t19),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t18, -t19, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q5z, -t20),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q5z, 0, t21),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t20, -t21, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, q6z, -t22),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -q6z, 0, t23),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, t22, -t23, 0),
        ca.horzcat(1, 0, 0, 0, cz, -cy, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 1, 0, -cz, 0, cx, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 1, cy, -cx, 0, 0, 0, 0, 0, 0, 0),
        ca.horzcat(0, 0, 0, 0, 0, 0, 1, 0, 0, 0, dz, -dy),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 1, 0, -dz, 0, dx),
        ca.horzcat(0, 0, 0, 0, 0, 0, 0, 0, 1, dy, -dx, 0),
    )
    return (Z,)


def _home_pose(g):
    """Home pose in the geometry."""
    z_home = g[2]
    P0 = ca.vertcat(0, 0, z_home, 0, 0, 0)
    return (P0,)


def _sketch(P, theta, g):
    """The robot drawn as line segments (columns 2k and 2k+1: the ends of segment k), mm."""
    x = P[0]
    y = P[1]
    z = P[2]
    roll = P[3]
    pitch = P[4]
    yaw = P[5]
    Rb = g[0]
    Rp = g[1]
    beta1 = g[4]
    beta2 = g[5]
    beta3 = g[6]
    beta4 = g[7]
    beta5 = g[8]
    beta6 = g[9]
    pi1 = g[10]
    pi2 = g[11]
    pi3 = g[12]
    pi4 = g[13]
    pi5 = g[14]
    pi6 = g[15]
    b1x = g[16]
    b1y = g[17]
    b1z = g[18]
    b2x = g[19]
    b2y = g[20]
    b2z = g[21]
    b3x = g[22]
    b3y = g[23]
    b3z = g[24]
    b4x = g[25]
    b4y = g[26]
    b4z = g[27]
    b5x = g[28]
    b5y = g[29]
    b5z = g[30]
    b6x = g[31]
    b6y = g[32]
    b6z = g[33]
    q1x = g[34]
    q1y = g[35]
    q1z = g[36]
    q2x = g[37]
    q2y = g[38]
    q2z = g[39]
    q3x = g[40]
    q3y = g[41]
    q3z = g[42]
    q4x = g[43]
    q4y = g[44]
    q4z = g[45]
    q5x = g[46]
    q5y = g[47]
    q5z = g[48]
    q6x = g[49]
    q6y = g[50]
    q6z = g[51]
    t0 = Rb*ca.cos(beta1) + b1x
    t1 = Rb*ca.cos(beta2) + b2x
    t2 = Rb*ca.cos(beta3) + b3x
    t3 = Rb*ca.cos(beta4) + b4x
    t4 = Rb*ca.cos(beta5) + b5x
    t5 = Rb*ca.cos(beta6) + b6x
    t6 = Rp*ca.cos(pi1) + q1x
    t7 = ca.cos(yaw)
    t8 = ca.cos(pitch)
    t9 = t7*t8
    t10 = ca.sin(roll)
    t11 = ca.sin(yaw)
    t12 = t10*t11
    t13 = ca.sin(pitch)
    t14 = ca.cos(roll)
    t15 = t14*t7
    t16 = t12 + t13*t15
    t17 = Rp*ca.sin(pi1) + q1y
    t18 = t11*t14
    t19 = t10*t7
    t20 = t13*t19 - t18
    t21 = q1z*t16 + t17*t20 + t6*t9 + x
    t22 = Rp*ca.cos(pi2) + q2x
    t23 = Rp*ca.sin(pi2) + q2y
    t24 = q2z*t16 + t20*t23 + t22*t9 + x
    t25 = Rp*ca.cos(pi3) + q3x
    t26 = Rp*ca.sin(pi3) + q3y
    t27 = q3z*t16 + t20*t26 + t25*t9 + x
    t28 = Rp*ca.cos(pi4) + q4x
    t29 = Rp*ca.sin(pi4) + q4y
    t30 = q4z*t16 + t20*t29 + t28*t9 + x
    t31 = Rp*ca.cos(pi5) + q5x
    t32 = Rp*ca.sin(pi5) + q5y
    t33 = q5z*t16 + t20*t32 + t31*t9 + x
    t34 = Rp*ca.cos(pi6) + q6x
    t35 = Rp*ca.sin(pi6) + q6y
    t36 = q6z*t16 + t20*t35 + t34*t9 + x
    t37 = Rb*ca.sin(beta1) + b1y
    t38 = Rb*ca.sin(beta2) + b2y
    t39 = Rb*ca.sin(beta3) + b3y
    t40 = Rb*ca.sin(beta4) + b4y
    t41 = Rb*ca.sin(beta5) + b5y
    t42 = Rb*ca.sin(beta6) + b6y
    t43 = t11*t8
    t44 = t13*t18 - t19
    t45 = t12*t13 + t15
    t46 = q1z*t44 + t17*t45 + t43*t6 + y
    t47 = q2z*t44 + t22*t43 + t23*t45 + y
    t48 = q3z*t44 + t25*t43 + t26*t45 + y
    t49 = q4z*t44 + t28*t43 + t29*t45 + y
    t50 = q5z*t44 + t31*t43 + t32*t45 + y
    t51 = q6z*t44 + t34*t43 + t35*t45 + y
    t52 = t14*t8
    t53 = t10*t8
    t54 = q1z*t52 - t13*t6 + t17*t53 + z
    t55 = q2z*t52 - t13*t22 + t23*t53 + z
    t56 = q3z*t52 - t13*t25 + t26*t53 + z
    t57 = q4z*t52 - t13*t28 + t29*t53 + z
    t58 = q5z*t52 - t13*t31 + t32*t53 + z
    t59 = q6z*t52 - t13*t34 + t35*t53 + z
    segments = ca.vertcat(
        ca.horzcat(t0, t1, t1, t2, t2, t3, t3, t4, t4, t5, t5, t0, t21, t24, t24, t27, t27, t30, t30, t33, t33, t36, t36, t21, t0, t21, t1, t24, t2, t27, t3, t30, t4, t33, t5, t36),
        ca.horzcat(t37, t38, t38, t39, t39, t40, t40, t41, t41, t42, t42, t37, t46, t47, t47, t48, t48, t49, t49, t50, t50, t51, t51, t46, t37, t46, t38, t47, t39, t48, t40, t49, t41, t50, t42, t51),
        ca.horzcat(b1z, b2z, b2z, b3z, b3z, b4z, b4z, b5z, b5z, b6z, b6z, b1z, t54, t55, t55, t56, t56, t57, t57, t58, t58, t59, t59, t54, b1z, t54, b2z, t55, b3z, t56, b4z, t57, b5z, t58, b6z, t59),
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
