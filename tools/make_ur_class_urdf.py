#!/usr/bin/python3
"""Writes campaigns/files/robots/ur-class.urdf: a six-joint, UR5e-class arm.

Source (docs/assumptions.md, "The ur-class arm"): Universal Robots, "DH parameters for
calculations of kinematics and dynamics" (UR5e row): standard DH d, a, alpha; link masses; and
centres of mass in the standard DH frames. The source gives no inertia tensors: each link is
taken as a solid cylinder of its mass about its long axis, with the radii and lengths Universal
Robots' ROS description (ur_description, ur5e physical_parameters.yaml) uses for the same purpose.

The URDF uses the modified-DH form of the same chain, so that each joint turns about its own
frame's z axis: joint i's <origin> is Tx(a_{i-1}) Rx(alpha_{i-1}) Tz(d_i) written as
xyz = (a_{i-1}, -sin(alpha_{i-1}) d_i, cos(alpha_{i-1}) d_i), rpy = (alpha_{i-1}, 0, 0).
Link i's frame is modified-DH frame i; the standard-DH frame i (where UR gives the centre of
mass) is that frame moved by Tx(a_i) Rx(alpha_i). The inertials are written with a non-zero
rpy where the cylinder's axis is not a frame axis, so the file exercises the full tensor.
"""
import math
import os
import sys

import numpy as np

D = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996]
A = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0]
ALPHA = [math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0]
MASS = [3.761, 8.058, 2.846, 1.37, 1.3, 0.365]
COM_STD = [[0, -0.02561, 0.00193], [0.2125, 0, 0.11336], [0.15, 0, 0.0265],
           [0, -0.0018, 0.01634], [0, 0.0018, 0.01634], [0, 0, -0.001159]]
# Cylinder (radius, length, long axis in the standard-DH frame) per link.
CYL = [(0.06, 0.15, 'z'), (0.06, 0.425, 'x'), (0.06, 0.392, 'x'),
       (0.06, 0.12, 'z'), (0.06, 0.12, 'z'), (0.0375, 0.0345, 'z')]
NAMES = ["shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"]
LINKS = ["shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link"]
EFFORT = [150, 150, 150, 28, 28, 28]           # UR5e joint sizes 3 and 1 [N m]
VELOCITY = [3.14, 3.14, 3.14, 6.28, 6.28, 6.28]  # [rad/s]


def rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rpy_of(r):
    """Roll-pitch-yaw (URDF: R = Rz(y) Ry(p) Rx(r)) of a rotation matrix."""
    pitch = math.asin(-max(-1.0, min(1.0, r[2, 0])))
    roll = math.atan2(r[2, 1], r[2, 2])
    yaw = math.atan2(r[1, 0], r[0, 0])
    return roll, pitch, yaw


def f(x):
    return repr(float(round(x, 15)) + 0.0)


def main(out):
    lines = ['<?xml version="1.0"?>',
             '<!-- A six-joint UR5e-class arm, written by tools/make_ur_class_urdf.py (sources there and in',
             '     docs/assumptions.md, "The ur-class arm"). No visual or collision geometry. -->',
             '<robot name="ur-class">',
             '  <link name="world"/>',
             '  <link name="base_link"/>',
             '  <joint name="world_fixed" type="fixed">',
             '    <parent link="world"/>', '    <child link="base_link"/>',
             '    <origin xyz="0 0 0" rpy="0 0 0"/>', '  </joint>']
    parent = "base_link"
    for i in range(6):
        a_prev = A[i - 1] if i > 0 else 0.0
        al_prev = ALPHA[i - 1] if i > 0 else 0.0
        xyz = (a_prev, -math.sin(al_prev) * D[i], math.cos(al_prev) * D[i])
        # Centre of mass and cylinder axis in link i's (modified-DH) frame.
        r_std = rx(ALPHA[i])
        com = np.array([A[i], 0, 0]) + r_std @ np.array(COM_STD[i])
        radius, length, axis = CYL[i]
        m = MASS[i]
        along = 0.5 * m * radius ** 2
        perp = m * (3 * radius ** 2 + length ** 2) / 12
        # The cylinder's principal frame: its axis is z of the inertial frame.
        r_cyl = np.eye(3) if axis == 'z' else np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]])  # Ry(90 deg): z -> x
        r_in = r_std @ r_cyl
        roll, pitch, yaw = rpy_of(r_in)
        lines += [f'  <link name="{LINKS[i]}">', '    <inertial>',
                  f'      <origin xyz="{f(com[0])} {f(com[1])} {f(com[2])}" rpy="{f(roll)} {f(pitch)} {f(yaw)}"/>',
                  f'      <mass value="{m}"/>',
                  f'      <inertia ixx="{f(perp)}" iyy="{f(perp)}" izz="{f(along)}" ixy="0" ixz="0" iyz="0"/>',
                  '    </inertial>', '  </link>',
                  f'  <joint name="{NAMES[i]}" type="revolute">',
                  f'    <parent link="{parent}"/>', f'    <child link="{LINKS[i]}"/>',
                  f'    <origin xyz="{f(xyz[0])} {f(xyz[1])} {f(xyz[2])}" rpy="{f(al_prev)} 0 0"/>',
                  '    <axis xyz="0 0 1"/>',
                  f'    <limit lower="-6.283185307179586" upper="6.283185307179586" effort="{EFFORT[i]}" velocity="{VELOCITY[i]}"/>',
                  '  </joint>']
        parent = LINKS[i]
    lines += ['  <link name="tool0"/>', '  <joint name="flange_fixed" type="fixed">',
              f'    <parent link="{parent}"/>', '    <child link="tool0"/>',
              '    <origin xyz="0 0 0" rpy="0 0 0"/>', '  </joint>', '</robot>', '']
    with open(out, "w") as fh:
        fh.write("\n".join(lines))


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "campaigns", "files", "robots", "ur-class.urdf"))
