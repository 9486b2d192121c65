"""Efforts on a joint's coordinate: actuators (a torque or force given as a value, a motor,
a PD or PID controller, a value a sampled controller holds) and stops (one-sided
spring-dampers at a coordinate's bounds), and the compiled laws and programs they read.

Each function returns the effort ``tau`` along the joint's coordinate (a torque about a
revolute axis, a force along a prismatic one); ``kernels.forces`` applies it to the child
and, opposite, to the parent.  Time reaches the kernels as the model's clock, a
joint-space entry filled like a drive's (``qfull[clock] = t``).

Sources (a value with its rate): ``CONSTANT`` (the number at the source's offset), a table
of time (``tables.LINEAR``/``PCHIP``: value and slope), or a ``PROGRAM`` (a stack-machine
program, ``kernels.programs``) stored among the element's numbers as ``[n_ops, n_consts,
n_vars, ops (2 n_ops), consts, variable codes]``.  A variable code ``k >= 0`` reads
``qfull[k]``, ``-k - 1`` reads ``ufull[k]``; ``X_VAR`` and ``V_VAR`` read the law's own
``x`` and ``v`` (a spring's elongation and its rate, a joint's offset and speed).

Actuator numbers (``force_data[off:]``, written by ``compiled.actuator_packing``):
``[type, prismatic, clock slot (-1: none), limit, a, b, ki, gear, held, n_carried,
gravity (3), setpoint, feed-forward, (frame, mass) of each body the joint carries]``;
``a, b`` are ``kp, kd`` (PD, PID) or the stall torque and no-load speed (motor); ``held``
(a PID's integral term, a sampled controller's effort) and ``feed-forward`` (the computed
torque) are written between compiled stretches (``integrate.sampled``).
"""

from .linalg3 import mat_vec
from .programs import STACK, evaluate
from .tables import NO_TABLE, table_eval
from .views import UNCOUNTED, c_view
from .internal import internal

TORQUE, MOTOR, PD, PID, HELD = 0, 1, 2, 3, 4
TYPES = {"torque": TORQUE, "motor": MOTOR, "pd": PD, "pid": PID, "held": HELD}
CONSTANT, PROGRAM = 0, 4                  # source modes besides the tables' LINEAR, PCHIP
X_VAR, V_VAR = -(1 << 40), -(1 << 40) - 1
#: where each number sits in an actuator's block
(A_TYPE, A_PRISMATIC, A_CLOCK, A_LIMIT, A_GAIN, A_RATE, A_KI, A_GEAR, A_HELD, A_CARRIED,
 A_GRAVITY, A_SETPOINT, A_FEEDFORWARD, A_BODIES) = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 13, 14, 15
#: floats of scratch a program needs: its variables (at most ``MAX_VARS``) and the stack
MAX_VARS = 32
PROGRAM_WORK = MAX_VARS + STACK


@internal(**UNCOUNTED)
def program_value(data, off, t, x, v, qfull, ufull, work):
    """The value of the program stored at ``data[off]`` (layout above) at time ``t``, with
    the law's ``x``, ``v``; ``work``: ``PROGRAM_WORK`` floats."""
    n_ops, n_consts, n_vars = int(data[off]), int(data[off + 1]), int(data[off + 2])
    ops = c_view(data, off + 3, (n_ops, 2))
    consts = c_view(data, off + 3 + 2 * n_ops, (n_consts,))
    codes = off + 3 + 2 * n_ops + n_consts
    y = work[0:MAX_VARS]
    for k in range(n_vars):
        code = int(data[codes + k])
        if code == X_VAR:
            y[k] = x
        elif code == V_VAR:
            y[k] = v
        elif code >= 0:
            y[k] = qfull[code]
        else:
            y[k] = ufull[-code - 1]
    return evaluate(ops, consts, 0, n_ops, t, y, work[MAX_VARS:PROGRAM_WORK])


@internal(**UNCOUNTED)
def source_value(data, off, mode, t, x, v, qfull, ufull, work):
    """``(value, rate)`` of a source: a constant (rate 0), a table of ``t`` (its slope),
    or a program (rate 0: a program's rate is a second program)."""
    if mode == CONSTANT:
        return data[off], 0.0
    if mode == PROGRAM:
        return program_value(data, off, t, x, v, qfull, ufull, work), 0.0
    table_eval(data, off, mode, t, work)
    return work[0], work[1]


@internal(**UNCOUNTED)
def clock(data, off, qfull):
    """The time, from the model's clock entry (0 for an actuator that does not read it)."""
    slot = int(data[off + A_CLOCK])
    return qfull[slot] if slot >= 0 else 0.0


@internal(**UNCOUNTED)
def gravity_effort(data, off, i, com, R, r, e, c, lever):
    """The effort that balances gravity on the bodies joint ``i`` carries (the
    generalised gravity force of its coordinate, negated): for a revolute joint
    ``-e . sum (c_b - r_i) x m_b g``, for a prismatic one ``-e . sum m_b g``; ``e`` the
    joint's world axis."""
    g = data[off + A_GRAVITY:off + A_GRAVITY + 3]
    prismatic = data[off + A_PRISMATIC] != 0.0
    tau = 0.0
    for k in range(int(data[off + A_CARRIED])):
        b = int(data[off + A_BODIES + 2 * k])
        m = data[off + A_BODIES + 2 * k + 1]
        if prismatic:
            tau -= m * (e[0] * g[0] + e[1] * g[1] + e[2] * g[2])
            continue
        mat_vec(R[b], com[b], c)
        for q in range(3):
            lever[q] = r[b, q] + c[q] - r[i, q]
        # e . (lever x m g)
        tau -= m * (e[0] * (lever[1] * g[2] - lever[2] * g[1])
                    + e[1] * (lever[2] * g[0] - lever[0] * g[2])
                    + e[2] * (lever[0] * g[1] - lever[1] * g[0]))
    return tau


@internal(**UNCOUNTED)
def actuator_effort(data, off, row, q, u, qfull, ufull, i, com, R, r, e, work):
    """The effort of the actuator whose numbers start at ``data[off]`` on the coordinate
    ``q`` (speed ``u``) of joint ``i`` (world axis ``e``); ``row``: its ``force_int`` row
    (sources at ``row[4:6]``, ``row[6:8]``)."""
    kind = int(data[off + A_TYPE])
    t = clock(data, off, qfull)
    if kind == HELD:
        tau = data[off + A_HELD]
    elif kind == TORQUE:
        tau = source_value(data, row[4], row[5], t, q, u, qfull, ufull, work)[0]
    elif kind == MOTOR:
        # a DC motor's torque-speed line scaled by its command c: tau_m = c tau_s - (tau_s /
        # w_0) w_m, or c times a torque-speed table; the joint gets gear * tau_m
        gear = data[off + A_GEAR]
        command = source_value(data, row[4], row[5], t, q, u, qfull, ufull, work)[0]
        speed = gear * u
        if row[7] != NO_TABLE:
            table_eval(data, row[6], row[7], speed, work)
            torque = command * work[0]
        else:
            stall, no_load = data[off + A_GAIN], data[off + A_RATE]
            torque = stall * (command - speed / no_load)
        limit = data[off + A_LIMIT]
        torque = min(max(torque, -limit), limit)
        return gear * torque
    else:                                   # PD, PID: the held integral term in A_HELD
        if row[5] == CONSTANT:
            setpoint, rate = data[off + A_SETPOINT], 0.0
        else:
            setpoint, rate = source_value(data, row[4], row[5], t, q, u, qfull, ufull, work)
            if row[7] == PROGRAM:
                rate = program_value(data, row[6], t, q, u, qfull, ufull, work)
        tau = (data[off + A_GAIN] * (setpoint - q) + data[off + A_RATE] * (rate - u)
               + data[off + A_HELD] + data[off + A_FEEDFORWARD])
        if data[off + A_CARRIED] > 0.0:
            tau += gravity_effort(data, off, i, com, R, r, e, work[0:3], work[3:6])
    limit = data[off + A_LIMIT]
    return min(max(tau, -limit), limit)


@internal(**UNCOUNTED)
def stop_effort(data, off, q, u, acc, want):
    """A joint stop: zero between ``lower`` and ``upper`` (``data[off:off + 4]`` = lower,
    upper, stiffness, damping); beyond a bound by ``d``, ``-(k d + c u)`` pushing back
    and never pulling into the stop.  Adds its potential ``k d^2 / 2`` and the power of
    its damping to ``acc``."""
    lower, upper, k, c = data[off], data[off + 1], data[off + 2], data[off + 3]
    if q > upper:
        d = q - upper
    elif q < lower:
        d = q - lower
    else:
        return 0.0
    tau = -(k * d + c * u)
    if tau * d > 0.0:                        # the damper would pull: the surfaces part
        tau = 0.0
    if want:
        acc[0] += 0.5 * k * d * d
        acc[1] += (tau + k * d) * u          # all power but the spring's
    return tau
