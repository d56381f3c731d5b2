"""Column layout of every table of a world's state and of the step's scratch: the one place where a
column, a parameter slot or a statistics slot is given its number.

Bodies live in two tables: ``bf`` (float64, capacity x ``BF_COLS``) and ``bi`` (int64, capacity x
``BI_COLS``).  Constraints (springs, rods, cables) live in ``kf``/``ki``, shapes in ``sf``/``si``,
contact points in ``cf``/``ci``.  The step reads its tunables from ``params_f``/``params_i`` and writes
counts and profile totals to ``stats``; the sequential-impulse solver works on solver-body rows ``sb``
and, for many contacts, on contact bundles ``wide_f``/``wide_i``.  Passing a few packed tables keeps the
fixed cost of a kernel call small.

Prefixes: body columns have none (``POS``, ``FLAGS``), ``F_`` body flags; ``S_`` shape columns; ``K_``
constraint columns, ``KT_`` constraint types, ``KF_`` constraint flags; ``W_`` world scalars; ``C_``
contact columns, ``CP_`` contact flags; ``PF_``/``PI_`` parameter slots; ``STAT_`` statistics slots;
``SB_`` solver-body columns; ``WB_``/``WI_`` bundle fields.
"""
from ..collision.broadphase import ALIVE as _BROADPHASE_ALIVE
from ..collision.broadphase import STATIC as _BROADPHASE_STATIC

# --- bodies, float table bf ---------------------------------------------------------------
POS = 0            # position of the centre of mass (m), 3 columns
QUAT = 3           # orientation (w, x, y, z), 4 columns
VEL = 7            # linear velocity (m/s), 3
OMEGA = 10         # angular velocity, world frame (rad/s), 3
INV_MASS = 13      # 1/m (1/kg); 0 for static bodies
INV_I = 14         # inverse inertia tensor, body frame (1/(kg m^2)), 9 columns row-major
FORCE = 23         # user force accumulator (N), 3; cleared after each step
TORQUE = 26        # user torque accumulator (N m), 3; cleared after each step
PREV_POS = 29      # Verlet: position at the previous step (m), 3
FRICTION = 32      # dynamic (sliding) Coulomb coefficient
STATIC_FRICTION = 33  # static (sticking) Coulomb coefficient
RESTITUTION = 34   # coefficient of restitution in [0, 1]
ROLLING = 35       # rolling friction coefficient (m): resisting torque = rolling * normal force
MASS = 36          # m (kg); inf for static bodies
I_BODY = 37        # inertia tensor, body frame (kg m^2), 9 columns row-major
V_FREE = 46        # velocity after integrating forces, before the constraint solver (m/s), 3
W_FREE = 49        # angular velocity after integrating forces, before the solver (rad/s), 3
X_PRED = 52        # position the integrator predicts without constraints (m), 3
Q_PRED = 55        # orientation the integrator predicts without constraints, 4
SLEEP_TIME = 59    # seconds the body has been nearly at rest
POS0 = 60          # position at the start of the step (m), 3: the solver updates separations from it
DTHETA = 63        # rotation vector accumulated since the start of the step (rad), 3
TORSION = 66       # torsional friction (m): resisting torque about the contact normal <= torsion * normal force
LINEAR_DAMPING = 67   # linear damping (1/s): dv/dt = -c v
ANGULAR_DAMPING = 68  # angular damping (1/s): domega/dt = -c omega
BF_COLS = 69
#: The material columns, in the order ``World._material`` validates them.
MATERIAL = (FRICTION, STATIC_FRICTION, RESTITUTION, ROLLING, TORSION, LINEAR_DAMPING, ANGULAR_DAMPING)


# --- bodies, int table bi -----------------------------------------------------------------
FLAGS = 0          # bit field, see F_* below
SHAPE_START = 1    # first row of the body's shapes in the shape table
SHAPE_COUNT = 2    # number of shapes
GROUP = 3          # collision group bits
MASK = 4           # collision mask bits
ISLAND = 5         # island id of the last step (-1: none)
BI_COLS = 6

F_ALIVE = _BROADPHASE_ALIVE     # slot holds a body (a removed body's slot is free until reused)
F_STATIC = _BROADPHASE_STATIC   # never moves (the broad phase never pairs two of them)
F_SENSOR = 4       # detects overlaps, exerts no force
F_SLEEPING = 8     # resting island, not integrated until woken
F_RESTART = 16     # Verlet: the previous position is unknown (new body or velocity/position set by hand)
F_ISOTROPIC = 32   # inertia tensor is a multiple of the identity (spheres, cubes): rotation needs no matrices
F_CCD_ALWAYS = 64  # add_body(ccd=True): impacts taken in time order even when slow for its size (world ccd on)
F_CCD_NEVER = 128  # add_body(ccd=False): never swept (no motion in its box, no time-of-impact ordering)
F_JOINTED = 256    # has a ball, hinge, slider or fixed joint: pairs of bodies so joined do not collide
F_KINEMATIC = 512  # moved by its velocities only (infinite mass): pushes and carries, is never pushed

# --- shapes, float table sf and int table si ------------------------------------------------
S_PARAMS = 0       # N_SHAPE_PARAMS kernel parameters (see collision/shape_types.py)
S_LOCAL_POS = 8    # position of the shape in its body's frame (m), 3
S_LOCAL_QUAT = 11  # orientation of the shape in its body's frame, 4
S_RADIUS = 15      # bounding radius about the shape's origin (m), inf for unbounded shapes
SF_COLS = 16

S_TYPE = 0         # shape type code
S_BODY = 1         # owning body row
S_OFF_F = 2        # offset of the shape's bulk geometry in geom_f
S_OFF_I = 3        # offset of the shape's bulk geometry in geom_i
SI_COLS = 4

# --- constraints (springs, rods, cables, joints), float table kf and int table ki ----------------------
K_ANCHOR_A = 0     # anchor on body a, a's local frame (m), 3
K_ANCHOR_B = 3     # anchor on body b, b's local frame, or a world point when b is the world (m), 3
K_LENGTH = 6       # rest length (spring), length (rod) or maximum length (cable) (m)
K_STIFFNESS = 7    # spring constant k (N/m)
K_DAMPING = 8      # damping coefficient c (N s/m)
K_BREAKING = 9     # breaking force (N); inf: unbreakable
K_FORCE = 10       # force the constraint applied to body a in the last step (N), 3
K_IMPULSE = 13     # accumulated impulse along the axis (rods, cables), warm start (N s)
# ball, hinge, slider and fixed joints (dynamics/joint_rows.py)
K_REF_QUAT = 14    # a's orientation relative to b's at creation, conj(q_b) q_a (b the world: q_a), 4
K_AXIS_A = 18      # the hinge's or slider's axis in a's frame (unit), 3
K_AXIS_B = 21      # the same axis in b's frame, or in the world frame when b is the world (unit), 3
K_LOWER = 24       # lower limit of the hinge's angle (rad) or the slider's position (m)
K_UPPER = 25       # upper limit, likewise
K_MOTOR_SPEED = 26  # the motor's target angular speed (rad/s) or speed (m/s)
K_MOTOR_MAX = 27   # the motor's largest torque (N m) or force (N)
K_ROW_IMPULSE = 28  # accumulated impulse of each of the joint's rows in the last sub-step, warm start, JOINT_ROWS
K_SUM_LINEAR = 37  # linear impulse the joint gave a over the step so far (N s), 3
K_SUM_ANGULAR = 40  # angular impulse it gave a about a's centre of mass over the step so far (N m s), 3
K_TORQUE = 43      # torque the joint applied to a about the joint's anchor in the last step (N m), 3
KF_COLS = 46
#: rows of a joint: point or perpendicular (0-2), angular (3-5), lower limit (6), upper limit (7), motor (8)
JOINT_ROWS = 9

K_TYPE = 0         # constraint type, see C_* below
K_BODY_A = 1       # body row of a
K_BODY_B = 2       # body row of b, -1 for the world
K_FLAGS = 3        # KF_* bits
KI_COLS = 4

KT_SPRING = 0
KT_ROD = 1
KT_CABLE = 2
KT_BALL = 3        # the anchors coincide
KT_HINGE = 4       # the anchors coincide; a turns relative to b about the axis only
KT_SLIDER = 5      # a moves relative to b along the axis only, without turning
KT_FIXED = 6       # a keeps its pose relative to b
KF_ALIVE = 1
KF_BROKEN = 2
KF_LIMITS = 4      # the hinge's angle or the slider's position stays within [K_LOWER, K_UPPER]
KF_MOTOR = 8       # a motor drives the hinge's angular speed or the slider's speed

# --- world state ws (float64) -------------------------------------------------------------------
W_TIME = 0         # simulated time (s)
W_PREV_DT = 1      # length of the last sub-step (s), for Verlet
WS_COLS = 2

# --- contact points, float table cf and int table ci (one row per contact point) -------------------
C_POINT = 0        # contact point, world (m), midway between the surfaces, 3
C_NORMAL = 3       # unit normal from body a to body b, 3
C_DEPTH = 6        # penetration depth at detection (m); <= 0: speculative gap
C_RA = 7           # contact point relative to a's centre of mass (m), 3
C_RB = 10          # contact point relative to b's centre of mass (m), 3
C_T1 = 13          # first tangent of the contact basis, 3
C_T2 = 16          # second tangent, 3
C_MASS_N = 19      # effective mass along the normal, 1 / (J M^-1 J^T) (kg)
C_MASS_T1 = 20     # effective mass along t1 (kg)
C_MASS_T2 = 21     # effective mass along t2 (kg)
C_LAMBDA_N = 22    # accumulated normal impulse (N s)
C_LAMBDA_T1 = 23   # accumulated friction impulse along t1 (N s)
C_LAMBDA_T2 = 24   # accumulated friction impulse along t2 (N s)
C_LAMBDA_R = 25    # accumulated rolling and torsional angular impulse, world vector (N m s), 3
C_MU_D = 28        # combined dynamic friction coefficient
C_MU_S = 29        # combined static friction coefficient
C_E = 30           # combined restitution
C_ROLL = 31        # combined rolling friction (m)
C_VN0 = 32         # relative normal velocity before the solve (m/s), for restitution
C_MAX_N = 33       # largest normal impulse in the step (N s), for restitution
C_ADJ_SEP = 34     # separation at detection, for updating it from the bodies' motion (m)
C_SUM_N = 35       # normal impulse applied over the whole step (N s)
C_SUM_T = 36       # friction impulse applied over the whole step, world vector (N s), 3
C_TORSION = 39     # combined torsional friction (m)
C_PAIR_SLIP = 40   # how fast the pair's bodies slid past each other at the last step's end (m/s; a new contact:
#                    as this step began): their centres' relative velocity across the contact normal
# the body-pair cache (pipeline/pair_cache.py), as the narrow phase found the point:
C_KEEP_POSE = 41   # body b's centre of mass (m, 3) and orientation (4) in body a's frame
C_KEEP_A = 48      # the point on a's surface in a's frame (m), 3
C_KEEP_B = 51      # the point on b's surface in b's frame (m), 3
C_KEEP_N = 54      # the normal in a's frame, 3
C_KEEP_REACH = 57  # how far apart (m) the pair test reported points: its prediction
CF_COLS = 58

C_BODY_A = 0
C_BODY_B = 1
C_SHAPE_A = 2
C_SHAPE_B = 3
C_FEATURE = 4
C_FLAGS = 5        # bit field, see CP_* below
CI_COLS = 6

CP_SLIDING = 1     # friction saturated (dynamic coefficient applies)
CP_SENSOR = 2      # a sensor takes part: reported, not solved
CP_MATCHED = 4     # warm-started from last step's contact with the same features
CP_RESTING = 8     # a resting pair's contact kept from the cache (both bodies asleep or static): reported, not solved

# --- step parameters, float params_f (tunables travel as arguments, never as globals) ---------------
PF_DT = 0
PF_GRAVITY = 1          # 3 values (m/s^2)
PF_SPECULATIVE = 4      # speculative distance (m)
PF_CONTACT_HERTZ = 5    # stiffness of contact position correction (Hz)
PF_CONTACT_ZETA = 6     # its damping ratio
PF_JOINT_HERTZ = 7      # stiffness of rod/cable position correction (Hz)
PF_JOINT_ZETA = 8       # its damping ratio
PF_MAX_PUSH = 9         # fastest overlap removal (m/s)
PF_SLIDE_SPEED = 10     # tangential speed above which a new contact slides (m/s)
PF_TOLERANCE = 11       # adaptive iterations stop when no velocity changes more than this (m/s)
PF_SLEEP_LINEAR = 12    # rest tolerance, linear (m/s)
PF_SLEEP_ANGULAR = 13   # rest tolerance, angular (rad/s)
PF_TIME_TO_SLEEP = 14   # seconds at rest before an island sleeps (<= 0: never)
PF_RESTITUTION_SPEED = 15  # closing speed below which no bounce is applied (m/s)
PF_SWEEP = 16           # 1: predict contacts along the step's motion (continuous collision), 0: only at rest
PF_PENALTY_HERTZ = 17   # penalty scheme: frequency of the contact springs (Hz)
PF_LCP_SOR = 18         # LCP scheme: over-relaxation factor of projected Gauss-Seidel, in (0, 2)
PF_MIN_INTERVAL = 19    # shortest interval a step may be cut into at an impact (s): dt / 2**max_halvings
PF_STEP_DT = 20         # the whole step's length (s), of which the interval PF_DT is a part (time stepping)
PF_LEN = 21

# --- step parameters, int params_i ------------------------------------------------------------------
PI_INTEGRATOR = 0       # index into dynamics.integrators.INTEGRATORS
PI_SUBSTEPS = 1
PI_ITERATIONS = 2       # most velocity iterations per sub-step
PI_BROADPHASE = 3       # code of collision.broadphase.METHODS
PI_SOLVER = 4           # SEQUENTIAL_IMPULSE, PENALTY or LCP
PI_LCP_SWEEPS = 5       # LCP scheme: most projected Gauss-Seidel sweeps per solve
PI_PROFILE = 6          # 1: add each stage's processor cycles to stats (World.profiling)
PI_THREADS = 7          # threads of the sequential-impulse contact passes (dynamics/contact_regions.py)
PI_TOI_MODE = 8         # which impacts end an interval and are resolved at its start: TOI_* below
PI_TOI_SPLIT = 9        # 1: the step may stop before solving and ask for a shorter interval (T_LIMIT)
PI_DETECT = 10          # 1: the step only detects contacts (no prediction) and returns (retroactive mode)
PI_TURN_SUBSTEPS = 11   # most sub-steps a fast-turning body may ask for (automatic sub-steps); 0: PI_SUBSTEPS exactly
PI_ADAPTIVE = 12        # 1: deep stacks may take more than PI_ITERATIONS passes (World.adaptive_iterations)
PI_SOLVE_ORDER = 13     # index into state.params.SOLVE_ORDERS: the contacts' order in the passes (World.solve_order)
PI_PAIR_CACHE = 14      # 1: a pair that has hardly moved keeps last step's contact points (World.pair_cache)
PI_LEN = 15

# solve orders (PI_SOLVE_ORDER), as listed in state.params.SOLVE_ORDERS
COLOURED = 0            # colour bundles (dynamics/contact_bundles.py) when there are enough contacts
BOTTOM_UP = 1           # one by one, level by level of the support depth (dynamics/support_depth.py)

# time-of-impact modes (PI_TOI_MODE); every mode drops speculative contacts that no motion can reach
TOI_NONE = 0            # fixed steps, continuous collision off: nothing more
TOI_FAST = 1            # continuous collision: bodies fast for their size (or add_body(ccd=True))
TOI_ALL = 2             # conservative advancement: every body's new contacts

SEQUENTIAL_IMPULSE = 0  # solver codes, in the order of World's solver names
PENALTY = 1
LCP = 2

# --- statistics, int64 stats, written by the step ---------------------------------------------------
STAT_PAIRS = 0          # candidate pairs found by the broad phase
STAT_CONTACTS = 1       # contact points found by the narrow phase
STAT_ITERATIONS = 2     # velocity iterations used in the step (all sub-steps)
STAT_CACHED = 3         # contact points of the last completed step: the rows of the cache table
STAT_CACHE_SIDE = 4     # which of the world's two contact tables is the cache (0 or 1); flips every step
# with PI_PROFILE on, the step also adds to these running totals (the World clears them):
STAT_PROFILED_STEPS = 5  # steps profiled
STAT_SUM_PAIRS = 6      # candidate pairs, summed over the profiled steps
STAT_SUM_CONTACTS = 7   # contact points, summed
STAT_SUM_ITERATIONS = 8  # velocity iterations, summed
STAT_PREVIOUS = 9       # rows of the table that was the cache before the last step (the contacts it began with)
STAT_KEPT = 10          # 1 if the last step kept its cache as it stood: no contact new, every one resting (the
#                         cache is then also the table the step began with; nothing was copied or swapped)
STAT_CYCLES = 11        # processor cycles of each stage of pipeline.stages.STAGES, one slot per stage

# --- time stepping, float time_f: what the step's time-of-impact stage reports to the stepping loop ------
T_LIMIT = 0             # the interval the step asks for when it stopped with SPLIT (s)
T_RESOLVED = 1          # impacts resolved at the start of the interval
T_DROPPED = 2           # speculative contacts dropped as unreachable
TIME_COLS = 4

# --- impacts resolved at an interval's start, float impact_f, one row per contact of the interval ------
IMP_N = 0               # normal impulse (N s)
IMP_T = 1               # friction impulse, world vector (N s), 3
IMP_SUMS = 4            # the columns above: the impulses
IMP_APPROACH = 4        # fastest approach along the normal before a resolution (m/s, >= 0), for contact events
IMPACT_COLS = 5

# --- solver bodies, float sb: the solver's compact view of a body (dynamics/solver_bodies.py) --------
SB_INV_MASS = 0         # 1/m (1/kg); 0 for a body that cannot move
SB_INV_I = 1            # R I_body^-1 R^T, row-major (1/(kg m^2)), 9
SB_V = 10               # linear velocity (m/s), 3
SB_W = 13               # angular velocity (rad/s), 3
SB_DP = 16              # displacement since the step began (m), 3
SB_DTHETA = 19          # rotation vector since the step began (rad), 3
SB_ISO = 22             # s if I_w^-1 = s E (spheres, cubes, and every body that cannot move: s = 0), else -1
SB_COLS = 24            # 23 used, padded to three 64-byte cache lines

# --- push bodies, float pb: each body's pseudo-velocity of the sub-step's position correction (split impulses,
# dynamics/contact_solver.py), one 64-byte line per row; rows like the solver bodies' (pad and sink rows last)
PB_V = 0                # pseudo linear velocity (m/s), 3
PB_W = 3                # pseudo angular velocity (rad/s), 3
PB_COLS = 8             # 6 used, padded to one cache line

# --- contact bundles (dynamics/contact_bundles.py): wide_f fields, one block of LANES values each ----
WB_NORMAL = 0           # 3
WB_RA = 3               # 3
WB_RB = 6               # 3
WB_T1 = 9               # 3
WB_T2 = 12              # 3
WB_MASS_N = 15
WB_MASS_T1 = 16
WB_MASS_T2 = 17
WB_MU = 18              # the friction coefficient that applies (static while sticking, dynamic once sliding)
WB_LAMBDA_N = 19
WB_LAMBDA_T1 = 20
WB_LAMBDA_T2 = 21
WB_MAX_N = 22
WB_VN0 = 23
WB_NEW = 24             # 1 for a contact not warm-started from last step, else 0
WB_ADJ_SEP = 25         # separation at detection (m)
WB_SEPARATION = 26      # current separation (m), from the bodies' motion (load_bundle_bodies)
WB_INV_MASS_A = 27
WB_INV_I_A = 28         # 9, row-major world inverse inertia (right after the inverse mass)
WB_INV_MASS_B = 37
WB_INV_I_B = 38         # 9
WB_SUM_N = 47           # impulses applied over the step's sub-steps
WB_SUM_T = 48           # 3 (right after the normal total)
WB_LAMBDA_P = 51        # accumulated push (split) impulse of the sub-step's position correction (N s)
WB_ROLL = 52            # combined rolling friction (m)
WB_TORSION = 53         # combined torsional friction (m)
WB_LAMBDA_R = 54        # accumulated rolling and torsional angular impulse, world vector (N m s), 3
BUNDLE_FIELDS = 57
# wide_i blocks of LANES ints
WI_READ_A = 0           # solver-body row read for a
WI_READ_B = 1           # and for b
WI_WRITE_A = 2          # row written for a (the sink row for a body that cannot move)
WI_WRITE_B = 3          # and for b
WI_CONTACT = 4          # the lane's contact (-1 for a pad lane)
WI_TURNING = 5          # 1 in every lane if some lane's body has a world inverse inertia that turns with it
WI_ROLLING = 6          # 1 in every lane if some lane has rolling or torsional friction or an angular impulse
BUNDLE_ROWS = 7
