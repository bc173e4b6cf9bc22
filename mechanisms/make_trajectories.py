"""Regenerate the bundled example trajectories (run from the repository root).

paper_2dof_traj.csv: positions only (the solver derives rates and accelerations by spline);
bendix_wrist_traj.csv: positions, rates and accelerations of an analytic motion;
rack_axis_traj.csv (m), helical_reduction_traj.csv and planetary_3p_traj.csv (rad): analytic,
with rates and accelerations.
"""
import numpy as np

from gearcli.io.trajectory import write_trajectory

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

# rack_axis: the carriage's slide Jx (m): a 0.15 m stroke out and back with a superposed
# faster wiggle (speeds to 0.6 m/s, accelerations to 4 m/s^2)
q = 0.15 * np.sin(w * t) + 0.01 * np.sin(4 * w * t)
qd = 0.15 * w * np.cos(w * t) + 0.04 * w * np.cos(4 * w * t)
qdd = -0.15 * w**2 * np.sin(w * t) - 0.16 * w**2 * np.sin(4 * w * t)
write_trajectory("mechanisms/rack_axis_traj.csv", ["Jx"], t, q[:, None], qd[:, None], qdd[:, None])

# helical_reduction: the output shaft Jout (rad), forwards and back against the constant
# resisting torque
q = 1.5 * np.sin(w * t) * (1 + 0.2 * np.cos(2 * w * t))
qd = 1.5 * w * (np.cos(w * t) * (1 + 0.2 * np.cos(2 * w * t)) - 0.4 * np.sin(w * t) * np.sin(2 * w * t))
qdd = 1.5 * w**2 * (-np.sin(w * t) * (1 + 0.2 * np.cos(2 * w * t)) - 0.8 * np.cos(w * t) * np.sin(2 * w * t)
                    - 0.8 * np.sin(w * t) * np.cos(2 * w * t))
write_trajectory("mechanisms/helical_reduction_traj.csv", ["Jout"], t, q[:, None], qd[:, None], qdd[:, None])

# planetary_3p: the carrier JC (rad), two turns out and back with a superposed faster
# oscillation (sun = 3.5 x carrier: to ~40 rad/s at the motor)
q = 2.0 * np.pi * np.sin(0.5 * w * t) + 0.3 * np.sin(3 * w * t)
qd = np.pi**2 * np.cos(0.5 * w * t) + 0.9 * w * np.cos(3 * w * t)
qdd = -0.5 * np.pi**3 * np.sin(0.5 * w * t) - 2.7 * w**2 * np.sin(3 * w * t)
write_trajectory("mechanisms/planetary_3p_traj.csv", ["JC"], t, q[:, None], qd[:, None], qdd[:, None])


def quintic_moves(t, stops):
    """q, qd, qdd (N,) of rest-to-rest quintic moves: stops [(t_start, t_end, q_from, q_to)],
    dwelling between them."""
    q, qd, qdd = np.full_like(t, stops[0][2]), np.zeros_like(t), np.zeros_like(t)
    for t0, t1, a, b in stops:
        T, d = t1 - t0, b - a
        tau = np.clip((t - t0) / T, 0.0, 1.0)
        inside = (t >= t0) & (t <= t1)
        q = np.where(t >= t0, a + d * (10 * tau**3 - 15 * tau**4 + 6 * tau**5), q)
        qd = np.where(inside, d / T * (30 * tau**2 - 60 * tau**3 + 30 * tau**4), qd)
        qdd = np.where(inside, d / T**2 * (60 * tau - 180 * tau**2 + 120 * tau**3), qdd)
    return q, qd, qdd


# cobot_joint: a pick-and-place cycle of the output J2 (rad): carry the part from -1 to +1 rad in
# 2 s (1.875 rad/s at most: 1790 rpm at the wave generator), dwell, place it (attach:part 0 from
# 2.5 s), swing back empty in 2 s, dwell, pick the next one (attach:part 1 from 5.5 s); 6 s.
tc = np.linspace(0.0, 6.0, 6001)
q, qd, qdd = quintic_moves(tc, [(0.0, 2.0, -1.0, 1.0), (3.0, 5.0, 1.0, -1.0)])
attach = ((tc < 2.5) | (tc >= 5.5)).astype(float)
np.savetxt("mechanisms/cobot_joint_traj.csv", np.column_stack([tc, q, qd, qdd, attach]), delimiter=",",
           header="t,q:J2,qd:J2,qdd:J2,attach:part", comments="", fmt="%.17g")

# cobot_6axis: J1..J6 (rad), 4 s of smooth motion at 1 kHz, output speeds to ~1.5 rad/s
# (150 rad/s = 1430 rpm at the wave generators), carrying the part throughout
t6 = np.linspace(0.0, 4.0, 4001)
amp = np.array([1.2, 0.6, 0.9, 1.0, 1.2, 1.5])
freq = np.array([0.25, 0.35, 0.3, 0.45, 0.4, 0.5]) * 2 * np.pi
phase = np.array([0.0, 0.4, 0.8, 1.2, 1.6, 2.0])
off = np.array([0.0, -0.6, 1.2, -0.5, 0.0, 0.0])
arg = freq * t6[:, None] + phase
q6, qd6, qdd6 = off + amp * np.sin(arg), amp * freq * np.cos(arg), -amp * freq**2 * np.sin(arg)
np.savetxt("mechanisms/cobot_6axis_traj.csv", np.column_stack([t6, q6, qd6, qdd6, np.ones_like(t6)]), delimiter=",",
           header=",".join(["t"] + [f"{p}:J{i}" for p in ("q", "qd", "qdd") for i in range(1, 7)] + ["attach:part"]),
           comments="", fmt="%.17g")
# the same cycle at 250 Hz (every 4th sample) for designs/cobot_6axis_select.yaml: select
# verifies a design per candidate part, and the peaks and means of this smooth motion move
# by less than 0.1 % at the coarser rate
np.savetxt("mechanisms/cobot_6axis_traj_250hz.csv", np.column_stack([t6, q6, qd6, qdd6, np.ones_like(t6)])[::4],
           delimiter=",", header=",".join(["t"] + [f"{p}:J{i}" for p in ("q", "qd", "qdd") for i in range(1, 7)]
                                          + ["attach:part"]), comments="", fmt="%.17g")

# rv_turret: the first axis J1 (rad) swinging -90 -> +90 deg in 1.5 s, dwelling 0.5 s, and back:
# a 4 s cycle (3.93 rad/s at most at the output: 4540 rpm at the RV input)
tr = np.linspace(0.0, 4.0, 4001)
q, qd, qdd = quintic_moves(tr, [(0.0, 1.5, -np.pi / 2, np.pi / 2), (2.0, 3.5, np.pi / 2, -np.pi / 2)])
write_trajectory("mechanisms/rv_turret_traj.csv", ["J1"], tr, q[:, None], qd[:, None], qdd[:, None])

# screw_lift: the carriage Jz (m): lift the part 0.15 m in 1.2 s, dwell, place it (attach:part 0
# from 1.4 s), lower empty in 1.2 s, dwell, pick the next (attach:part 1 from 3.0 s); 3.2 s.
# 0.234 m/s at most: 295 rad/s (2810 rpm) of the screw, below its 314 rad/s critical speed
ts = np.linspace(0.0, 3.2, 3201)
q, qd, qdd = quintic_moves(ts, [(0.0, 1.2, 0.0, 0.15), (1.6, 2.8, 0.15, 0.0)])
attach = ((ts < 1.4) | (ts >= 3.0)).astype(float)
np.savetxt("mechanisms/screw_lift_traj.csv", np.column_stack([ts, q, qd, qdd, attach]), delimiter=",",
           header="t,q:Jz,qd:Jz,qdd:Jz,attach:part", comments="", fmt="%.17g")

# worm_lift: the drum Jd (rad): raise the load a turn and a half (0.47 m of rope) in 2 s, hold,
# lower it back in 2 s (under power: the stage is self-locking), hold; 5 s.  Drum to 8.8 rad/s,
# the worm to 353 rad/s (3380 rpm).
tw = np.linspace(0.0, 5.0, 5001)
q, qd, qdd = quintic_moves(tw, [(0.0, 2.0, 0.0, 3 * np.pi), (2.5, 4.5, 3 * np.pi, 0.0)])
write_trajectory("mechanisms/worm_lift_traj.csv", ["Jd"], tw, q[:, None], qd[:, None], qdd[:, None])

# scara: J1, J2 (rad) and the quill Jz (m, + up): pick a part (quill down 80 mm and up, the part
# attached from 0.3 s), swing to the place (1 s), place it (down and up, detached from 2.0 s),
# swing back; 3.4 s at 1 kHz.  J1 and J2 to 3.75 rad/s (motor 1: 18.75 rad/s, the wave
# generator 188 rad/s), the quill to 0.5 m/s (the screw: 157 rad/s).
tsc = np.linspace(0.0, 3.4, 3401)
j1 = quintic_moves(tsc, [(0.65, 1.65, -1.0, 1.0), (2.3, 3.3, 1.0, -1.0)])
j2 = quintic_moves(tsc, [(0.65, 1.65, 1.2, -0.8), (2.3, 3.3, -0.8, 1.2)])
jz = quintic_moves(tsc, [(0.0, 0.3, 0.0, -0.08), (0.35, 0.65, -0.08, 0.0), (1.65, 1.95, 0.0, -0.08),
                         (2.0, 2.3, -0.08, 0.0)])
attach = ((tsc >= 0.3) & (tsc < 2.0)).astype(float)
cols = [tsc] + [np.asarray(x) for k in range(3) for x in (j1[k], j2[k], jz[k])] + [attach]
np.savetxt("mechanisms/scara_traj.csv", np.column_stack(cols), delimiter=",",
           header="t,q:J1,q:J2,q:Jz,qd:J1,qd:J2,qd:Jz,qdd:J1,qdd:J2,qdd:Jz,attach:part", comments="", fmt="%.17g")
