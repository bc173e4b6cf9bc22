"""Regenerate the bundled example trajectories (run from the repository root).

paper_2dof_traj.csv: positions only (the solver derives rates and accelerations by spline);
bendix_wrist_traj.csv: positions, rates and accelerations of an analytic motion.
"""
import numpy as np

from gearcli.trajectory import write_trajectory

t = np.linspace(0.0, 2.0, 2001)          # 2 s at 1 kHz
w = np.pi

# paper_2dof: shoulder J1 and elbow J2 (rad)
q = np.column_stack([1.2 * np.sin(w * t) + 0.3 * np.sin(3 * w * t),
                     0.9 * np.sin(1.5 * w * t + 0.4)])
write_trajectory("mechanisms/paper_2dof_traj.csv", ["J1", "J2"], t, q)

# bendix_wrist: J1 (roll of the housing), J2 (pitch of the yoke), J3 (tool roll) (rad)
A = np.array([1.0, 0.7, 2.0])
f = np.array([1.0, 1.5, 0.75]) * w
ph = np.array([0.0, 0.5, 1.0])
q = A * np.sin(f * t[:, None] + ph)
qd = A * f * np.cos(f * t[:, None] + ph)
qdd = -A * f**2 * np.sin(f * t[:, None] + ph)
write_trajectory("mechanisms/bendix_wrist_traj.csv", ["J1", "J2", "J3"], t, q, qd, qdd)

# geared_arm.urdf: shoulder, elbow (rad) and the left finger's slide (m: the angle columns'
# unit rule applies to revolute joints; a prismatic joint's q is in m)
q = np.column_stack([0.8 * np.sin(w * t), 0.6 * np.sin(1.5 * w * t + 0.3), 0.01 + 0.005 * np.sin(2 * w * t)])
write_trajectory("mechanisms/geared_arm_traj.csv", ["shoulder", "elbow", "finger_left_joint"], t, q)
