"""The whole-body controller's weights, gains, contact model and solver settings.

Task weights :math:`w` scale squared residuals of accelerations [m/s^2, rad/s^2], and of
forces per unit of the robot's mass [N/kg] (a force error counts as the whole-body
acceleration it would cause); gains turn position and velocity errors into accelerations,
:math:`a^* = a_{ff} + k_p e + k_d \\dot e` (:math:`k_p` [1/s^2], :math:`k_d` [1/s]). So one
set of defaults serves the 9 kg quadruped and the 33 kg biped.

OSQP's defaults here (``DEFAULT_OSQP_SETTINGS``): a loose ADMM tolerance (1e-4) checked every
5 iterations, because polishing then solves the identified active set exactly (equalities
to ~1e-12), warm starting from the previous tick, adaptive :math:`\\rho` (Cassie's QP does
not converge at any fixed :math:`\\rho` tried, 0.003 to 10), and two Ruiz equilibration
passes (``scaling``) rather than OSQP's ten. Measured on 200 recorded ticks of the
Hovershoes' velocity-steps under callgrind (instructions a tick, which do not vary with the
machine's load):

- the matrices change every tick, so OSQP scales them again at every update: ten passes
  cost a tenth of the tick for no fewer iterations (6.54 -> 5.89 M, 19.9 iterations either
  way; torques within 2e-5 N m on Cassie's recorded rides, 4e-4 N m on the dog's);
- polishing takes 18 % of the tick (it orders and factors a new KKT matrix at every
  solve). ADMM to 1e-6 without it took 5.34 M and moved the torques by at most 1.5e-3 N m,
  but the Hovershoes circle, seed 1, then fell at 21.63 s (a shoe tipped), where polished,
  and unpolished at 1e-5 or 1e-7, it rode to the end (seeds 0 and 2-9 rode either way,
  seeds 0-9 all ride polished): a ride that sensitive is not a test of the tolerance, but
  polishing is the setting every figure here was measured with.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Literal

from ridempc.errors import ConfigError
from ridempc.friction import SHAPES
from ridempc.solvers import QP_KINDS

__all__ = ["DEFAULT_OSQP_SETTINGS", "SOLVERS", "TrackingGains", "WbcSettings"]

DEFAULT_OSQP_SETTINGS: MappingProxyType[str, float | int | bool] = MappingProxyType(
    {
        "eps_abs": 1e-4,
        "eps_rel": 1e-4,
        "check_termination": 5,
        "max_iter": 2000,
        "polishing": True,
        "polish_refine_iter": 3,
        "warm_starting": True,
        "adaptive_rho": True,
        "scaling": 2,
        "verbose": False,
    }
)


SOLVERS: tuple[str, ...] = QP_KINDS["wbc"].solvers  # the whole-body QP's, by name


@dataclass(frozen=True)
class TrackingGains:
    """Weight and PD gains of one tracking task.

    Attributes:
        weight: :math:`w` of the task's squared acceleration residual.
        kp: Stiffness :math:`k_p` [1/s^2].
        kd: Damping :math:`k_d` [1/s].
    """

    weight: float
    kp: float
    kd: float


@dataclass(frozen=True)
class WbcSettings:
    """Checked-by-construction settings of :class:`~ridempc.wbc.WholeBodyController`.

    Attributes:
        dt: Control period [s] (the joint targets integrate over it).
        track: The point the position targets refer to: ``com`` (centre of mass) or
            ``base`` (base origin).
        friction: Coulomb friction coefficient :math:`\\mu` [-]; the QP keeps each force in
            its inner pyramid :math:`|f_{t_k}| \\le (\\mu/\\sqrt2) f_n`
            (:mod:`ridempc.friction`); keep it below the true friction.
        pyramid: The pyramid's shape, ``box`` (above) or ``diamond``
            (:math:`|f_{t_1}| + |f_{t_2}| \\le \\mu f_n`; :data:`ridempc.friction.SHAPES`).
        springs: How the QP treats the description's leaf springs: ``passive`` (known
            torques :math:`-k (q - q_{ref})` from the measured deflection) or ``rigid``
            (held still, their torque free; see
            :class:`~ridempc.wbc.constraints.RigidSpringConstraint`).
        spring_damping: :math:`k_d` of rigid springs [1/s].
        min_normal_force: Least normal force on a site in contact [N].
        max_normal_force: Largest normal force on one site, in robot weights [-].
        orientation: Base orientation task.
        position: Centre-of-mass (or base) position task.
        swing: Swing-foot task (feet not in contact, with swing targets).
        posture: Motor-joint posture task.
        force_weight: Weight of each standing foot's force distance to the MPC's, per unit
            of whole-body acceleration [(kg/N)^2] (:class:`~ridempc.wbc.tasks.ContactForceTask`).
        site_force_weight: Weight of each contact site's distance to an even share of its
            foot's MPC force [(kg/N)^2].
        acceleration_regularisation: Weight of :math:`\\|\\ddot q\\|^2`.
        force_regularisation: Weight of :math:`\\|f\\|^2` [1/N^2].
        torque_regularisation: Weight of :math:`\\|\\tau\\|^2` [1/(N m)^2].
        loop_force_regularisation: Weight of :math:`\\|\\lambda\\|^2` [1/N^2].
        osqp: OSQP settings, over ``DEFAULT_OSQP_SETTINGS``.
        solver: The QP's solver, by name (``SOLVERS``): the registry's
            (:data:`~ridempc.solvers.QP_KINDS`), ``daqp`` (a dual active-set method, exact),
            or ``osqp`` (ADMM, polished; DAQP where it fails), to measure the choice in the
            closed loop (``ridempc bench --wbc-solver``).
    """

    dt: float = 0.002
    track: Literal["com", "base"] = "com"
    friction: float = 0.6
    pyramid: str = "box"
    springs: Literal["passive", "rigid"] = "passive"
    spring_damping: float = 20.0
    min_normal_force: float = 0.0
    max_normal_force: float = 2.0
    orientation: TrackingGains = TrackingGains(weight=100.0, kp=100.0, kd=20.0)
    position: TrackingGains = TrackingGains(weight=100.0, kp=100.0, kd=20.0)
    swing: TrackingGains = TrackingGains(weight=1000.0, kp=400.0, kd=40.0)
    posture: TrackingGains = TrackingGains(weight=1.0, kp=100.0, kd=20.0)
    force_weight: float = 1.0
    site_force_weight: float = 10.0
    acceleration_regularisation: float = 1e-4
    force_regularisation: float = 1e-6
    torque_regularisation: float = 1e-5
    loop_force_regularisation: float = 1e-8
    osqp: Mapping[str, float | int | bool] = field(default_factory=lambda: DEFAULT_OSQP_SETTINGS)
    solver: str = QP_KINDS["wbc"].solver

    def __post_init__(self) -> None:
        if self.dt <= 0.0:
            raise ConfigError(f"WBC settings: field 'dt': must be positive, got {self.dt}")
        if self.track not in ("com", "base"):
            raise ConfigError(
                f"WBC settings: field 'track': unknown '{self.track}' (valid: base, com)"
            )
        if self.springs not in ("passive", "rigid"):
            raise ConfigError(
                f"WBC settings: field 'springs': unknown '{self.springs}' (valid: passive, rigid)"
            )
        if self.friction <= 0.0:
            raise ConfigError(
                f"WBC settings: field 'friction': must be positive, got {self.friction}"
            )
        if self.solver not in SOLVERS:
            raise ConfigError(
                f"WBC settings: field 'solver': unknown '{self.solver}' "
                f"(valid: {', '.join(sorted(SOLVERS))})"
            )
        if self.pyramid not in SHAPES:
            raise ConfigError(
                f"WBC settings: field 'pyramid': unknown '{self.pyramid}' "
                f"(valid: {', '.join(SHAPES)})"
            )
        if not 0.0 <= self.min_normal_force:
            raise ConfigError("WBC settings: field 'min_normal_force': must be non-negative")
        if self.max_normal_force <= 0.0:
            raise ConfigError("WBC settings: field 'max_normal_force': must be positive")
