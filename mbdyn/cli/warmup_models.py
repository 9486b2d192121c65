"""The small model files ``mbdyn warmup`` runs (written to a temporary folder): each
exercises one route of the compiled kernels, as a user's model file of that kind would.
The kernels are compiled for argument *types*, not sizes or values: the workspace's
layout (a tree below 6 speeds, ``M u' = f``; 6 or more, the articulated bodies; a closed
loop), whether there are force elements (their tables are arrays, or ``None``) and
whether some are contacts between shapes.  So a two-link pendulum compiles what every
small tree needs, a six-link chain what every articulated-body run needs, each of them
with one force element what every such model with force elements needs, the model of every
kind of force element what one with contacts between shapes needs; events, drives and
outputs do not change the types."""

#: two links with inertia (2 speeds: ``M u' = f``), every output
PENDULUM = """
[model]
name = "warm-up pendulum"
gravity = [0, -9.81, 0]

[[bodies]]
name = "link1"
mass = 1.0
com = [0, -0.1, 0]
inertia = [1e-3, 1e-3, 1e-3]

[[bodies]]
name = "link2"
mass = 0.5
com = [0, -0.1, 0]
inertia = [1e-3, 1e-3, 1e-3]

[[joints]]
name = "theta1"
kind = "revolute"
parent = "ground"
child = "link1"
axis = "z"

[[joints]]
name = "theta2"
kind = "revolute"
parent = "link1"
child = "link2"
axis = "z"
position = [0, -0.2, 0]

[initial]
theta1 = 0.5
theta2 = -0.3

[simulation]
t_end = 0.05
integrator = "DOP853"
dt = 0.001

[outputs]
reactions = true
energy = true

[outputs.points]
tip = { frame = "link2", offset = [0, -0.2, 0] }
"""

#: six links, one of them on a spherical joint (8 speeds: the articulated-body route)
CHAIN = """
[model]
name = "warm-up chain"
gravity = [0, 0, -9.81]
""" + "".join(f"""
[[bodies]]
name = "b{k}"
mass = 1.0
com = [0.1, 0, 0]
inertia = [1e-3, 2e-3, 2e-3]

[[joints]]
name = "j{k}"
kind = "{'spherical' if k == 3 else 'revolute'}"
parent = "{'ground' if k == 0 else f'b{k - 1}'}"
child = "b{k}"
{'' if k == 3 else 'axis = "y"'}
position = [{0 if k == 0 else 0.2}, 0, 0]
""" for k in range(6)) + """
[simulation]
t_end = 0.02
dt = 0.001

[outputs]
reactions = true
energy = true
"""

#: every kind of force element (contacts between shapes too), tables, a drive, a compiled
#: law and an actuator reading
#: the clock (a block on springs, a rotor on a bearing, a ball on the floor)
FORCES = """
[model]
name = "warm-up forces"
gravity = [0, 0, -9.81]

[[bodies]]
name = "block"
mass = 1.0
inertia = [1e-2, 1e-2, 1e-2]

[[bodies]]
name = "rotor"
mass = 2.0
inertia = [1e-2, 2e-2, 2e-2]

[[bodies]]
name = "ball"
mass = 0.1
inertia = [1e-5, 1e-5, 1e-5]

[[joints]]
name = "x"
kind = "prismatic"
parent = "ground"
child = "block"
axis = "x"

[[joints]]
name = "spin"
kind = "revolute"
parent = "block"
child = "rotor"
axis = "x"
drive = "100*t"

[[joints]]
name = "z"
kind = "prismatic"
parent = "ground"
child = "ball"
axis = "z"
position = [1, 0, 0]

[initial]
x = 0.01
z = 0.05

[[forces]]
name = "spring"
kind = "spring-damper"
body_a = "ground"
point_a = [-0.5, 0, 0]
body_b = "block"
stiffness = 100
free_length = 0.5
damping = 1
preload = 1

[[forces]]
name = "table_spring"
kind = "spring-damper"
body_a = "ground"
point_a = [0.5, 0, 0]
body_b = "block"
free_length = 0.5
force_table = [[-1, -100], [0, 0], [1, 100]]
damping_table = [[-1, -1], [0, 0], [1, 1]]

[[forces]]
name = "hinge"
kind = "joint-spring-damper"
joint = "x"
stiffness = 10
damping = 0.1

[[forces]]
name = "mount"
kind = "bushing"
body_a = "block"
body_b = "ground"
stiffness = [10, 10, 10, 1, 1, 1]
damping = [0.1, 0.1, 0.1, 0.01, 0.01, 0.01]

[[forces]]
name = "journal"
kind = "bearing"
body = "rotor"
center = [0, 0, 0]
axis = "x"
speed = "spin"
speeds = [50, 200]
kxx = [1e3, 2e3]
kxy = 100
kyx = -100
kyy = [1e3, 2e3]
cxx = 1
cyy = 1

[[forces]]
name = "floor"
kind = "contact"
body = "ball"
radius = 0.02
stiffness = 1e5
restitution = 0.8
friction = 0.3

[[forces]]
name = "stop"
kind = "joint-stop"
joint = "z"
lower = -1
upper = 1
stiffness = 1e4

[[forces]]
name = "friction"
kind = "joint-spring-damper"
joint = "x"
law = "0.1*tanh(v/0.01)"

[[actuators]]
name = "push"
joint = "x"
kind = "pd"
kp = 10
kd = 1
setpoint = "0.01*sin(t)"

[[shapes]]
name = "ball_shape"
kind = "sphere"
body = "ball"
radius = 0.02

[[shapes]]
name = "ground_plane"
kind = "plane"
body = "ground"
normal = [0, 0, 1]

[[contacts]]
name = "touch"
pairs = [["ground_plane", "ball_shape"]]
stiffness = 1e5
restitution = 0.8
impact_speed = 1.0

[simulation]
t_end = 0.02
dt = 0.0005
max_step = 0.001

[outputs]
reactions = true
energy = true
"""

#: a crank-rocker four-bar closed by a loop joint, released with its crank turning: the
#: constrained route, the projection after each step, the loop's reactions
FOUR_BAR = """
[model]
name = "warm-up four-bar"
gravity = [0, -9.81, 0]

[[bodies]]
name = "crank"
mass = 0.5
com = [0.05, 0, 0]
inertia = [1e-4, 5e-4, 5e-4]

[[bodies]]
name = "coupler"
mass = 1.2
com = [0.175, 0, 0]
inertia = [1e-4, 1e-2, 1e-2]

[[bodies]]
name = "rocker"
mass = 1.0
com = [0.15, 0, 0]
inertia = [1e-4, 8e-3, 8e-3]

[[joints]]
name = "crank"
kind = "revolute"
parent = "ground"
child = "crank"
axis = "z"

[[joints]]
name = "coupler"
kind = "revolute"
parent = "crank"
child = "coupler"
axis = "z"
position = [0.1, 0, 0]

[[joints]]
name = "rocker"
kind = "revolute"
parent = "ground"
child = "rocker"
axis = "z"
position = [0.4, 0, 0]

[[joints]]
name = "pin_B"
kind = "revolute"
parent = "coupler"
child = "rocker"
axis = "z"
position = [0.35, 0, 0]
child_position = [0.3, 0, 0]
cut = true

[initial_speeds]
crank = 6.0

[guess]
coupler = 0.9
rocker = 1.9

[simulation]
t_end = 0.02
dt = 0.001

[outputs]
reactions = true
energy = true
"""


def _with_spring(text, joint):
    """The model ``text`` with one force element (a joint spring on ``joint``)."""
    return text + f"""
[[forces]]
name = "spring"
kind = "joint-spring-damper"
joint = "{joint}"
stiffness = 1.0
damping = 0.01
"""


#: ``{file stem: text}`` of the models above, and of the chain and the four-bar with a
#: force element
MODELS = {"pendulum": PENDULUM, "chain": CHAIN, "forces": FORCES, "four_bar": FOUR_BAR,
          "pendulum_forces": _with_spring(PENDULUM, "theta1"),
          "chain_forces": _with_spring(CHAIN, "j0"),
          "four_bar_forces": _with_spring(FOUR_BAR, "rocker")}
