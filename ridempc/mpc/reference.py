"""The MPC's reference: a motion-library trajectory picked for a commanded target.

:func:`select_reference` reads a pair's manifest and loads only the entries it needs: the
entry of the commanded kind whose target is the command, or else the two neighbouring
targets, blended linearly (:math:`\\alpha` = where the command lies between them) when
their contact schedules have the same phases (same modes and contacts; the phase durations
are blended too, each phase in its own normalised time), or else the nearest of the two.
A command beyond the library's targets gets the nearest entry. The skateboard's entries
differ in their number of pushes, so they are never blended; the Cassie pairs' are.

:meth:`MotionReference.sample` gives the reference at the MPC's times
:math:`t_0 + k \\Delta t`: states interpolated linearly between the library's nodes,
inputs averaged over each MPC step (the library holds them over its own intervals), mode
parameters and contacts of the interval each step starts in. After the end the rider rides
on steadily (:func:`steady_riding`, from the pair's dynamics): every state whose rate does
not depend on the inputs (positions, headings, angles) advances at its rate at the last
node, the others are held at the last node; a pair may have it settle into another
posture meanwhile (:mod:`ridempc.mpc.settle`).

The contact schedule comes from the entry: the forces are the inputs named
``f_<contact>_x|y|z``, and each phase of the entry's ``metadata.phases`` names where each
contact is (``board``, ``ground``, ``swing``); phases without contacts (the Cassie pairs)
keep every contact on the board. A missing, corrupt or inconsistent manifest or entry is a
:class:`~ridempc.errors.ConfigError` of one line naming the file.
"""

from __future__ import annotations

import re
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.library.format import EntryRecord
from ridempc.library.store import LibraryEntry, library_folder, load_entry, read_manifest
from ridempc.trajopt.schedule import Contact, Phase

__all__ = [
    "MotionReference",
    "ReferenceWindow",
    "reference_from_entry",
    "select_reference",
    "steady_riding",
]

Array = NDArray[np.float64]
_FORCE = re.compile(r"^f_(.+)_([xyz])$")
# [-] up to this many times, states_at goes row by row in floats: a tick reads one or two
_FEW_TIMES: int = 4


class ReferenceWindow(NamedTuple):
    """The reference over one MPC horizon.

    Attributes:
        times: :math:`t_0 + k \\Delta t`, k = 0..N [s].
        states: (N + 1) x nx.
        inputs: N x nu (forces of contacts not touching at a step's start are zero).
        parameters: N x n_p, the mode parameters of ``rates``.
        contacts: Per step, per contact, where it is at the step's start (N x n_c).
    """

    times: Array
    states: Array
    inputs: Array
    parameters: Array
    contacts: tuple[tuple[Contact, ...], ...]


@dataclass(frozen=True)
class MotionReference:
    """A trajectory to track, on the library's grid.

    Attributes:
        name: The entry's name, or ``<lo>+<hi>@<alpha>`` for a blend.
        kind: Kind of trajectory (``accelerate``, ``stop``, ``turn``).
        target: Its target [m/s].
        times: Node times from 0 [s] (M + 1).
        states: (M + 1) x nx.
        inputs: M x nu, held over each interval.
        parameters: M x n_p.
        state_names: Names of the states.
        input_names: Names of the inputs.
        contact_names: Contact names, in the order of the force inputs.
        force_index: Per contact, the input indices of its force (x, y, z), n_c x 3.
        phases: The entry's phases (mode, duration [s], per-contact places).
        schedule: Per interval, per contact, where it is, M x n_c.
        friction: The library's friction coefficient :math:`\\mu` [-].
        steady_rates: Rates at which states advance after the end (zero: held; see
            :func:`steady_riding`).
        settle_states: Offset the states reach ``settle_time`` after the end (None:
            none; :mod:`ridempc.mpc.settle`).
        settle_inputs: Offset the inputs reach then (None: none).
        settle_time: How long the offsets take to grow in [s].
        metadata: The entry's metadata (the lower one's for a blend), from which the
            pair rebuilds its ``rates``.
    """

    name: str
    kind: str
    target: float
    times: Array
    states: Array
    inputs: Array
    parameters: Array
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    contact_names: tuple[str, ...]
    force_index: NDArray[np.int64]
    phases: tuple[Phase, ...]
    schedule: tuple[tuple[Contact, ...], ...]
    friction: float
    steady_rates: Array
    metadata: dict[str, Any]
    settle_states: Array | None = None
    settle_inputs: Array | None = None
    settle_time: float = 0.0

    @cached_property
    def _input_integral(self) -> Array:
        """The inputs' running integral at the nodes, (M + 1) x nu."""
        return np.vstack([np.zeros(self.inputs.shape[1]), np.cumsum(self.inputs * self.dt, 0)])

    @property
    def min_board_share(self) -> float:
        """The library's least normal force on a contact standing on a board, in units of
        the weight per contact (``options.min_board_force``; 0 when the entry has none)."""
        options = self.metadata.get("options", {})
        value = options.get("min_board_force", 0.0) if isinstance(options, dict) else 0.0
        return float(value) if isinstance(value, int | float) else 0.0

    @property
    def duration(self) -> float:
        """Length of the trajectory [s]."""
        return float(self.times[-1] - self.times[0])

    @property
    def dt(self) -> float:
        """The library's grid step [s]."""
        return float(self.times[1] - self.times[0])

    def sample(self, t0: float, horizon: int, dt: float) -> ReferenceWindow:
        """The reference at :math:`t_0 + k \\Delta t` (see the module docstring).

        Args:
            t0: Time since the trajectory's start [s].
            horizon: N, the number of MPC steps.
            dt: MPC step :math:`\\Delta t` [s].
        """
        times = np.arange(horizon + 1, dtype=np.float64) * dt + t0
        end = self.times[-1]
        states = self.states_at(times)
        # Inputs averaged over each step: differences of their running integral.
        step = self.dt
        clipped = np.maximum(times, self.times[0])
        running = _interp_rows(clipped, self.times, self._input_integral)
        running += np.maximum(clipped - end, 0.0)[:, None] * self.inputs[-1]
        inputs = np.diff(running, axis=0) / dt
        before = times[:-1] < self.times[0]
        inputs[before] = self.inputs[0]
        if self.settle_inputs is not None:
            inputs += self._settled(times[:-1])[:, None] * self.settle_inputs
        interval = np.clip(
            np.floor((times[:-1] - self.times[0]) / step + 1e-9).astype(int),
            0,
            len(self.inputs) - 1,
        )
        contacts = tuple(self.schedule[j] for j in interval)
        for k, step_contacts in enumerate(contacts):
            for i, kind in enumerate(step_contacts):
                if kind is Contact.SWING:
                    inputs[k, self.force_index[i]] = 0.0
        parameters = self.parameters[interval]
        return ReferenceWindow(times, states, inputs, parameters, contacts)

    def states_at(self, times: Array) -> Array:
        """The states alone at ``times`` [s] since the start, rows as :meth:`sample`'s
        (held before the start, ridden on steadily after the end): what the 500 Hz tick
        reads, without the inputs, contacts and parameters of a whole window."""
        times = np.asarray(times, dtype=np.float64)
        if times.ndim == 1 and times.size <= _FEW_TIMES:
            return self._few_states_at(times.tolist())
        states = _interp_rows(times, self.times, self.states)
        states += np.maximum(times - self.times[-1], 0.0)[:, None] * self.steady_rates
        if self.settle_states is not None:
            states += self._settled(times)[:, None] * self.settle_states
        return states

    @cached_property
    def _grid(self) -> list[float]:
        """The node times as Python floats, for :meth:`_few_states_at`'s searches."""
        return [float(t) for t in self.times]

    def _few_states_at(self, times: list[float]) -> Array:
        """:meth:`states_at` row by row in Python floats, the same arithmetic element for
        element (so the same numbers to the bit): for the tick's one or two times, where
        the arrays' searches, clips and broadcasts cost more than the interpolation."""
        grid, states = self._grid, self.states
        last, end = len(grid) - 1, grid[-1]
        out = np.empty((len(times), states.shape[1]))
        for k, t in enumerate(times):
            upper = min(max(bisect_right(grid, t), 1), last)
            lower = upper - 1
            weight = min(max((t - grid[lower]) / (grid[upper] - grid[lower]), 0.0), 1.0)
            row = (1.0 - weight) * states[lower] + weight * states[upper]
            row += max(t - end, 0.0) * self.steady_rates
            if self.settle_states is not None:
                tau = min(max((t - end) / max(self.settle_time, 1e-9), 0.0), 1.0)
                row += tau * tau * (3.0 - 2.0 * tau) * self.settle_states
            out[k] = row
        return out

    def _settled(self, times: Array) -> Array:
        """How far the settle has gone at ``times``: :math:`3\\tau^2 - 2\\tau^3`,
        :math:`\\tau = (t - T) / t_{settle}` clipped to [0, 1]."""
        # np.minimum(np.maximum()): np.clip's wrapper costs some 5 us a call, three a tick
        tau = np.minimum(
            np.maximum((times - self.times[-1]) / max(self.settle_time, 1e-9), 0.0), 1.0
        )
        return tau * tau * (3.0 - 2.0 * tau)


def _interp_rows(t: Array, grid: Array, table: Array) -> Array:
    """:func:`numpy.interp` of every column of ``table`` (rows on the increasing ``grid``)
    at the times ``t``, held at the ends; one search for all columns."""
    # np.minimum(np.maximum()): np.clip's wrapper costs some 5 us a call, per tick
    upper = np.minimum(np.maximum(np.searchsorted(grid, t, side="right"), 1), len(grid) - 1)
    lower = upper - 1
    fraction = (t - grid[lower]) / (grid[upper] - grid[lower])
    weight = np.minimum(np.maximum(fraction, 0.0), 1.0)[:, None]
    return np.asarray((1.0 - weight) * table[lower] + weight * table[upper])


def _phases(path: Path, entry: LibraryEntry, n_contacts: int) -> tuple[Phase, ...]:
    """The entry's phases, each a whole number of intervals."""
    record = entry.record
    raw = record.metadata.get("phases")
    if not isinstance(raw, list) or not raw:
        raise ConfigError(f"{path}: metadata 'phases' is missing or empty")
    phases = []
    for j, phase in enumerate(raw):
        try:
            steps = round(float(phase["duration"]) / record.dt)
            places = phase.get("contacts", [Contact.BOARD.value] * n_contacts)
            contacts = tuple(Contact(p) for p in places)
            mode = str(phase["mode"])
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise ConfigError(f"{path}: metadata phase {j} is malformed ({exc})") from exc
        if len(contacts) != n_contacts or steps < 1:
            raise ConfigError(
                f"{path}: metadata phase {j} names {len(contacts)} contacts over {steps} "
                f"intervals, expected {n_contacts} contacts and at least one interval"
            )
        phases.append(Phase(mode, steps * record.dt, contacts))
    total = sum(round(p.duration / record.dt) for p in phases)
    if total != record.n_intervals:
        raise ConfigError(
            f"{path}: metadata phases last {total} intervals, the entry has {record.n_intervals}"
        )
    return tuple(phases)


def _force_layout(path: Path, input_names: Sequence[str]) -> tuple[tuple[str, ...], Any]:
    contacts: list[str] = []
    index: dict[str, dict[str, int]] = {}
    for j, name in enumerate(input_names):
        match = _FORCE.match(name)
        if match:
            contact, axis = match.groups()
            if contact not in index:
                contacts.append(contact)
                index[contact] = {}
            index[contact][axis] = j
    for contact in contacts:
        if set(index[contact]) != {"x", "y", "z"}:
            raise ConfigError(f"{path}: force of contact '{contact}' lacks a component")
    if not contacts:
        raise ConfigError(f"{path}: no force inputs (named f_<contact>_x|y|z)")
    return tuple(contacts), np.array([[index[c][a] for a in "xyz"] for c in contacts])


def steady_riding(reference: MotionReference, rates: ca.Function) -> MotionReference:
    """``reference`` riding on after its end: the states whose rates do not depend on the
    inputs advance at their rates at the last node (see the module docstring).

    Args:
        reference: The reference (its states held after the end).
        rates: The pair's :math:`f(x, u, p)` (e.g. ``Pair.rates(reference.metadata)``).
    """
    nx, nu = reference.states.shape[1], reference.inputs.shape[1]
    if (rates.size1_in(0), rates.size1_in(1)) != (nx, nu):
        raise ConfigError(
            f"reference '{reference.name}': {nx} states and {nu} inputs do not match the "
            f"dynamics' {rates.size1_in(0)} and {rates.size1_in(1)}"
        )
    x, u = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
    p = reference.parameters[-1]
    driven = np.array(ca.DM(ca.jacobian(rates(x, u, p), u).sparsity(), 1)).any(axis=1)
    value = np.asarray(rates(reference.states[-1], reference.inputs[-1], p)).ravel()
    return replace(reference, steady_rates=np.where(driven, 0.0, value))


def reference_from_entry(entry: LibraryEntry, path: Path | str) -> MotionReference:
    """A checked :class:`MotionReference` of one library entry (held after its end).

    Args:
        entry: The loaded entry.
        path: Its file (named in errors).

    Raises:
        ConfigError: The entry's metadata or names do not describe its contact schedule.
    """
    path = Path(path)
    contacts, force_index = _force_layout(path, entry.input_names)
    phases = _phases(path, entry, len(contacts))
    dt = entry.record.dt
    schedule = tuple(p.contacts for p in phases for _ in range(round(p.duration / dt)))
    options = entry.record.metadata.get("options", {})
    friction = options.get("friction") if isinstance(options, dict) else None
    if not isinstance(friction, int | float) or not friction > 0.0:
        raise ConfigError(f"{path}: metadata 'options.friction' is missing or not positive")
    states, inputs = entry.states, entry.inputs
    return MotionReference(
        name=entry.record.name,
        kind=entry.record.kind,
        target=float(entry.record.target),
        times=entry.times - entry.times[0],
        states=states,
        inputs=inputs,
        parameters=entry.parameters,
        state_names=entry.state_names,
        input_names=entry.input_names,
        contact_names=contacts,
        force_index=force_index,
        phases=phases,
        schedule=schedule,
        friction=float(friction),
        steady_rates=np.zeros(states.shape[1]),
        metadata=dict(entry.record.metadata),
    )


def _phase_bounds(reference: MotionReference) -> tuple[list[tuple[str, Any]], Array]:
    """Phases (mode and contacts) and their boundary times [s]."""
    keys = [(p.mode, p.contacts) for p in reference.phases]
    bounds = np.concatenate([[0.0], np.cumsum([p.duration for p in reference.phases])])
    return keys, bounds


def _blend(lo: MotionReference, hi: MotionReference, alpha: float) -> MotionReference | None:
    """Blend two references phase by phase, or None when their phases differ."""
    if (lo.state_names, lo.input_names, lo.contact_names) != (
        hi.state_names,
        hi.input_names,
        hi.contact_names,
    ) or not np.isclose(lo.dt, hi.dt):
        return None
    phases_lo, bounds_lo = _phase_bounds(lo)
    phases_hi, bounds_hi = _phase_bounds(hi)
    if phases_lo != phases_hi:
        return None
    step = lo.dt
    lengths = (1 - alpha) * np.diff(bounds_lo) + alpha * np.diff(bounds_hi)
    steps = np.maximum(1, np.round(lengths / step)).astype(int)

    def source(bounds: Array, nodes: bool) -> Array:
        out = []
        for i, n in enumerate(steps):
            fraction = (np.arange(n) + (0.0 if nodes else 0.5)) / n
            out.append(bounds[i] + fraction * (bounds[i + 1] - bounds[i]))
        if nodes:
            out.append(bounds[-1:])
        return np.concatenate(out)

    def nodes_of(ref: MotionReference, t: Array) -> Array:
        return np.column_stack([np.interp(t, ref.times, c) for c in ref.states.T])

    def intervals_of(ref: MotionReference, t: Array) -> Array:
        return np.clip(np.floor(t / ref.dt).astype(int), 0, len(ref.inputs) - 1)

    t_lo, t_hi = source(bounds_lo, True), source(bounds_hi, True)
    m_lo, m_hi = (
        intervals_of(lo, source(bounds_lo, False)),
        intervals_of(hi, source(bounds_hi, False)),
    )
    states = (1 - alpha) * nodes_of(lo, t_lo) + alpha * nodes_of(hi, t_hi)
    inputs = (1 - alpha) * lo.inputs[m_lo] + alpha * hi.inputs[m_hi]
    return MotionReference(
        name=f"{lo.name}+{hi.name}@{alpha:.3f}",
        kind=lo.kind,
        target=(1 - alpha) * lo.target + alpha * hi.target,
        times=np.arange(len(states), dtype=float) * step,
        states=states,
        inputs=inputs,
        parameters=lo.parameters[m_lo],
        state_names=lo.state_names,
        input_names=lo.input_names,
        contact_names=lo.contact_names,
        force_index=lo.force_index,
        phases=tuple(
            Phase(p.mode, n * step, p.contacts) for p, n in zip(lo.phases, steps, strict=True)
        ),
        schedule=tuple(lo.schedule[j] for j in m_lo),
        friction=lo.friction,
        steady_rates=np.zeros(states.shape[1]),
        metadata=dict(lo.metadata),
    )


def select_reference(
    robot: str,
    board: str,
    kind: str,
    target: float,
    folder: Path | None = None,
    interpolate: bool = True,
) -> MotionReference:
    """The reference for a commanded kind and target (see the module docstring).

    Args:
        robot: Robot name.
        board: Board name.
        kind: Kind of trajectory (``accelerate``, ...).
        target: Commanded target [m/s].
        folder: Library folder (default ``motion_library/<robot>-<board>``).
        interpolate: Blend the two neighbouring entries when they allow it.

    Raises:
        ConfigError: Missing or corrupt manifest or entry file (named), no entry of that
            kind (the valid kinds listed), or an entry that does not describe its schedule.
    """
    folder = folder or library_folder(robot, board)
    manifest = read_manifest(folder)
    records = sorted((e for e in manifest.entries if e.kind == kind), key=lambda e: e.target)
    if not records:
        kinds = sorted({e.kind for e in manifest.entries})
        raise ConfigError(
            f"{folder / 'manifest.json'}: no '{kind}' entries (valid: {', '.join(kinds)})"
        )

    def load(record: EntryRecord) -> MotionReference:
        return reference_from_entry(load_entry(folder, record), folder / record.file)

    targets = np.array([r.target for r in records])
    above = int(np.searchsorted(targets, target))
    exact = np.isclose(targets, target)
    if exact.any() or above == 0 or above == len(records):
        return load(records[int(np.argmin(np.abs(targets - target)))])
    lo, hi = records[above - 1], records[above]
    alpha = (target - lo.target) / (hi.target - lo.target)
    ref_lo, ref_hi = load(lo), load(hi)
    blended = _blend(ref_lo, ref_hi, alpha) if interpolate else None
    if blended is not None:
        return blended
    return ref_lo if alpha < 0.5 else ref_hi
