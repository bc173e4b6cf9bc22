"""The per-sample laws of the losses, written once for both paths (docs/concepts/losses.md).

Each function takes the algebra ``al`` (:mod:`gearcli.algebra`: numpy over the samples, or the
kernel's emitter) and values of it; the numpy reference (:mod:`.losses`, :mod:`.equations`)
and the generator (:mod:`.llvm.friction_terms`) call the same functions.  Every sign that
decides a direction is a sign of a rate formed from the joint rates (s_v, s_w) or of the
unknown itself (sigma), so an exact zero stays zero in any frames.

Power-flow elements (reducers, screws; :mod:`gearcli.model.power_flow`)
-----------------------------------------------------------------------
With u the element's lossless interaction (its unknown), w its drive rate, s_w = sign(w)
and sigma = sign(u), the factor on its input torque is c_r = 1/eta_f where sigma s_w = -1
(the input drives), eta_b where +1 (the output drives), 1 at rest.  Written without a branch
as c_r = 1 + delta,

    delta = A s_w^2 + B sigma s_w,   A = (1/eta_f + eta_b)/2 - 1,   B = (eta_b - 1/eta_f)/2,

delta is linear in u for given signs, so the sign rule resolves sigma as it does the
separating force's sign(t) (Eq. 14).  The element dissipates T0 |a| - delta u w >= 0 (T0 its
no-load running torque, |a| its speed).
"""
from __future__ import annotations


def joint_friction(al, F_c, F_v, qd):
    """The friction generalised force on a joint's child, -F_c sign(q') - F_v q' (N*m about the
    axis, or N along it; the parent takes the opposite), from the joint's own rate q': exactly
    +0 at rest (``0.0 - F_c``: no -0 for a viscous-only joint)."""
    return al.sub(al.signed(qd, 0.0 - F_c, F_c), al.mul(F_v, qd))


def mesh_loss(al, c, r_j, t, rate):
    """A geared mesh's power loss P = c |t| |theta'_{j,c}| r_j, W: loss factor c = 1 - eta,
    tooth force t (N), gear j's rate relative to the carrier (rad/s, from the joint rates) and
    its pitch radius r_j (m) (:mod:`.losses`)."""
    return al.mul(al.mul(al.mul(c, al.call("fabs", t)), al.call("fabs", rate)), r_j)


def power_flow_coefficients(al, speed, forward, backward, mode: int = 0) -> tuple:
    """(A, B) of delta = A s_w^2 + B sigma s_w (module docstring) at the element's speed,
    ``forward``, ``backward`` the (speeds, values) tables of eta_f, eta_b over it.

    ``mode`` 0: a reducer's or screw's factor c_r on its torque.  A belt's loss couple is two
    such elements of one circuit (:func:`gearcli.dynamics.losses.loss_couples`): 1 the couple on
    the driven pulley k where power flows j -> k, A = -B = (1 - eta_f)/2; 2 the couple on j
    where it flows k -> j, A = B = -(1 - eta_b)/2."""
    if mode == 0:
        inv_f, eta_b = al.div(1.0, al.interp(speed, forward)), al.interp(speed, backward)
        return al.sub(al.mul(0.5, al.add(inv_f, eta_b)), 1.0), al.mul(0.5, al.sub(eta_b, inv_f))
    if mode == 1:
        A = al.mul(0.5, al.sub(1.0, al.interp(speed, forward)))
        return A, al.neg(A)
    A = al.mul(-0.5, al.sub(1.0, al.interp(speed, backward)))
    return A, A


def power_flow_delta(al, A, B, sigma, s_w):
    """delta = c_r - 1 = A s_w^2 + B sigma s_w (sigma = sign(u), s_w = sign(w))."""
    return al.add(al.mul(A, al.mul(s_w, s_w)), al.mul(B, al.mul(sigma, s_w)))


def no_load_torque(al, T0, s_w):
    """A reducer's no-load running torque on its input about z_I, -T0 s_w (N*m; the housing
    takes the opposite), T0 >= 0 read at its speed."""
    return al.neg(al.mul(T0, s_w))


def element_loss(al, delta, u, w, T0, speed):
    """The power a power-flow element dissipates, T0 |a| - delta u w (W, >= 0; +0 at rest)."""
    return al.plus_zero(al.sub(al.mul(T0, speed), al.mul(al.mul(delta, u), w)))


def input_torque(al, delta, u, T0, s_w):
    """The torque a reducer exerts on its input about z_I, losses included: (1 + delta) u plus
    its no-load running torque -T0 s_w (N*m; ``gear:<p>:input_torque``)."""
    return al.sub(al.add(u, al.mul(delta, u)), al.mul(T0, s_w))
