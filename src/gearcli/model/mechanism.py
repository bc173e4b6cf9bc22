"""The mechanism model: frozen dataclasses that no algorithm mutates.

Frames and units
----------------
Every link has a frame.  Lengths in m, masses in kg, inertias in kg*m^2 about the centre of
mass with axes parallel to the link frame, angles in rad.  A revolute joint connects a
*parent* link to a *child* link.  Its geometry is normalised, whatever the file said, to

    child frame = parent frame * X_pj * Rz(q) * X_jc

where ``X_pj = (R_pj, p_pj)`` places the **joint frame** in the parent frame at q = 0 (its
z axis is the rotation axis) and ``X_jc = (R_jc, p_jc)`` places the child frame in the
rotated joint frame.  The joint frame after rotation, parent * X_pj * Rz(q), is fixed in
the child: its z is the joint axis and its x turns with the child.  For a D-H joint it is
Rz(theta)*Tz(d) of the parent frame.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .friction import JointFriction
from .loads import Load, with_payloads
from .ratings import BearingRating, GearRating, JointLimit, MotorModel, MotorRating
from .reducers import Reducer
from .screws import Screw
from .worms import Worm
from .belts import Belt


@dataclass(frozen=True, eq=False)
class Link:
    """A rigid body.  ``inertia`` is about the centre of mass, in link-frame axes."""

    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    path: str = ""


@dataclass(frozen=True, eq=False)
class Joint:
    """A one-degree-of-freedom joint (a real bearing) between ``parent`` and ``child``.

    ``type`` is ``"revolute"`` (q is an angle about the joint z axis) or ``"prismatic"``
    (q is a displacement along it).  ``source`` keeps the geometry as written in the file
    (``{"dh": {...}}`` or ``{"origin": {...}, "axis": [...]}``) for export.
    """

    name: str
    parent: str
    child: str
    R_pj: np.ndarray
    p_pj: np.ndarray
    R_jc: np.ndarray
    p_jc: np.ndarray
    type: str = "revolute"
    label: str | None = None
    source: dict = field(default_factory=dict)
    path: str = ""
    bearings: tuple[BearingRating, ...] | None = None   # rated bearings (design checks)
    limit: JointLimit | None = None                     # URDF <limit effort velocity>
    friction: JointFriction | None = None               # joints[].friction (model.friction)
    position_limits: tuple[float, float] | None = None  # (lower, upper), rad (m): simulate stops there


GEAR_KINDS = ("external", "internal", "bevel", "rack")


@dataclass(frozen=True, eq=False)
class GearPair:
    """A gear pair between links ``j`` and ``k``.

    Fundamental circuit equation (paper Eq. 8): theta_{j,c} = ratio * theta_{k,c}, with c
    the carrier and the angles measured about each joint's positive axis.  ``mesh_point``
    is the pitch point in the carrier frame (m); ``None`` means an ideal coupling with no
    tooth geometry.  ``kind == "rack"``: j is a pinion turning on a revolute joint and k a
    rack sliding on a prismatic joint relative to the carrier, q_{k,c} the rack's
    displacement along its axis (m), ``ratio`` = theta_j / x_k = +-1/r_j (rad/m).
    """

    name: str
    j: str
    k: str
    kind: str = "external"
    ratio: float | None = None
    teeth: tuple[int, int] | None = None
    mesh_point: np.ndarray | None = None
    carrier: str | None = None
    pressure_angle: float = np.deg2rad(20.0)
    cone_angles: tuple[float, float] | None = None
    path: str = ""
    # A coupling of two real joint coordinates, q_{joints[0]} = ratio * q_{joints[1]} (a URDF
    # <mimic>; j and k are the two joints' children).  Without mesh_point it is an ideal
    # coupling acting on the two joints (torque pair, reactions on each joint's parent).
    joints: tuple[str, str] | None = None
    rating: GearRating | None = None   # tooth rating (design checks)
    # Helical parallel-axis pair: helix angle beta (rad; pressure_angle is then the normal
    # one) and the hand of gear j ("right"/"left"; gear k: opposite for an external pair,
    # the same for an internal one).  See model.gears.helical_terms.
    helix_angle: float = 0.0
    hand: str | None = None
    # Mesh stiffness k, N/m (N*m/rad for an ideal coupling): the weight 1/k of the pair's
    # tooth force in a redundant gear set's load sharing (min sum t^2/k); None: equal.
    stiffness: float | None = None
    # Mesh loss factor c = 1 - efficiency in [0, 1) (gears[].loss_factor or .efficiency): the
    # mesh dissipates c |t| v_p, v_p the pitch-line speed relative to the carrier
    # (dynamics.losses.mesh_couple); 0 = lossless.
    loss_factor: float = 0.0
    # A coaxial reducer (kind strain_wave or cycloidal, model.reducers): j is its input, k its
    # output, carrier its housing, ratio the basic ratio i0; its efficiency, no-load torque,
    # torsional stiffness and catalogue rating.  None for a gear pair.
    reducer: Reducer | None = None
    # A ball or lead screw (kind screw, model.screws): j is the screw (revolute), k the nut
    # (prismatic) on the same line relative to the carrier, ratio e = theta_j / x_k (rad/m).
    screw: Screw | None = None
    # A worm pair (kind worm, model.worms): j is the worm, k the wheel; ratio from the geometry.
    worm: Worm | None = None
    # A timing belt (kind belt, model.belts): j the input pulley, k the output; ratio from the geometry.
    belt: Belt | None = None

    @property
    def lossy(self) -> bool:
        """True when the pair dissipates power: a mesh loss factor, or a drive element
        (reducer, screw, worm, belt) with losses."""
        return bool(self.loss_factor) or any(e is not None and e.lossy
                                             for e in (self.reducer, self.screw, self.worm, self.belt))


@dataclass(frozen=True, eq=False)
class Motor:
    """A motor driving input link ``link``; its stator is fixed in ``stator`` (default the
    input link's carrier in the canonical graph).  Its torque acts on ``link`` about the
    link's positive joint axis and, reversed, on the stator."""

    name: str
    link: str
    stator: str | None = None
    path: str = ""
    # A transmission (URDF <transmission>): ((joint, c), ...).  The motor's input rotation is
    # sum c * q_joint and its torque tau acts as c * tau about (along) each joint's axis, on
    # the joint's child and reversed on its parent.  Empty: the default above.
    joints: tuple[tuple[str, float], ...] = ()
    rating: MotorRating | None = None   # design checks
    model: MotorModel | None = None     # DC motor model (gearcli simulate, voltage columns)


@dataclass(frozen=True, eq=False)
class Mechanism:
    """A whole mechanism as read from a file.  ``lines`` maps source paths to lines."""

    name: str
    base: str
    end_effector: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    gears: tuple[GearPair, ...] = ()
    motors: tuple[Motor, ...] = ()
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    source: str = "<memory>"
    lines: dict = field(default_factory=dict, repr=False)   # hundreds of entries: not in repr
    # "chain": the independent coordinates are the paper's equivalent open-loop chain
    # base -> end_effector.  "tree": they are the joints of every link that is not the
    # first link j of a gear pair or coupling (a branched robot, e.g. a URDF humanoid).
    open_loop: str = "chain"
    warnings: tuple[str, ...] = ()  # input problems that were worked around (e.g. URDF)
    loads: tuple[Load, ...] = ()    # external loads on links (model.loads)
    # payloads that are picked and placed (``payloads:``): a Load with a mass and no wrench,
    # carried only where attached (:meth:`attached`; trajectory columns attach:<name>)
    payloads: tuple[Load, ...] = ()

    @property
    def has_losses(self) -> bool:
        """True when any gear pair has a loss factor, any reducer an efficiency below 1 or a
        no-load torque, or any joint has friction of its own or in its bearings."""
        return any(g.lossy for g in self.gears) or any(
            (j.friction is not None and j.friction.active) or any(b.friction_arm for b in j.bearings or ())
            for j in self.joints)

    def attached(self, names) -> "Mechanism":
        """The mechanism carrying the payloads ``names`` (an iterable of payload names): each
        becomes a load with its mass and inertia, rigidly attached to its link
        (:attr:`bodies`); it has no payloads left to attach."""
        from dataclasses import replace  # noqa: PLC0415
        names = set(names)
        return replace(self, loads=self.loads + tuple(p for p in self.payloads if p.name in names), payloads=())

    def link(self, name: str) -> Link:
        """The link called ``name``."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)

    @cached_property
    def bodies(self) -> tuple[Link, ...]:
        """The rigid bodies the dynamics moves: ``links`` with every payload's mass and
        inertia (``loads[].mass``, ``loads[].inertia``) merged into its link
        (:func:`~gearcli.model.loads.with_payloads`); the same order and names."""
        return with_payloads(self.links, self.loads)

    @property
    def link_names(self) -> list[str]:
        """Names of every link, in file order."""
        return [link.name for link in self.links]
