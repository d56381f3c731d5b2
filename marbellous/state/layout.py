"""Column layout of the world's packed state tables (structure of arrays, one row per object).

Bodies live in two tables: ``bf`` (float64, capacity x ``BF_COLS``) and ``bi`` (int64, capacity x
``BI_COLS``).  Constraints (springs, rods, cables) live in ``kf``/``ki``, shapes in ``sf``/``si``.
Passing a few packed tables keeps the fixed cost of a kernel call small (see ECOSYSTEM.md); the
column names below are the only place the layout is spelled out.
"""

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
BF_COLS = 66


# --- bodies, int table bi -----------------------------------------------------------------
FLAGS = 0          # bit field, see F_* below
SHAPE_START = 1    # first row of the body's shapes in the shape table
SHAPE_COUNT = 2    # number of shapes
GROUP = 3          # collision group bits
MASK = 4           # collision mask bits
ISLAND = 5         # island id of the last step (-1: none)
BI_COLS = 6

F_ALIVE = 1        # slot holds a body (removed bodies keep their slot, flag cleared)
F_STATIC = 2       # never moves
F_SENSOR = 4       # detects overlaps, exerts no force
F_SLEEPING = 8     # resting island, not integrated until woken
F_RESTART = 16     # Verlet: the previous position is unknown (new body or velocity/position set by hand)
F_ISOTROPIC = 32   # inertia tensor is a multiple of the identity (spheres, cubes): rotation needs no matrices

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

# --- constraints (springs, rods, cables), float table kf and int table ki ----------------------
K_ANCHOR_A = 0     # anchor on body a, a's local frame (m), 3
K_ANCHOR_B = 3     # anchor on body b, b's local frame, or a world point when b is the world (m), 3
K_LENGTH = 6       # rest length (spring), length (rod) or maximum length (cable) (m)
K_STIFFNESS = 7    # spring constant k (N/m)
K_DAMPING = 8      # damping coefficient c (N s/m)
K_BREAKING = 9     # breaking force (N); inf: unbreakable
K_FORCE = 10       # force the constraint applied to body a in the last step (N), 3
K_IMPULSE = 13     # accumulated impulse along the axis (rods, cables), warm start (N s)
KF_COLS = 14

K_TYPE = 0         # constraint type, see C_* below
K_BODY_A = 1       # body row of a
K_BODY_B = 2       # body row of b, -1 for the world
K_FLAGS = 3        # bit 0 alive, bit 1 broken
KI_COLS = 4

C_SPRING = 0
C_ROD = 1
C_CABLE = 2
KF_ALIVE = 1
KF_BROKEN = 2

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
C_LAMBDA_R = 25    # accumulated rolling-resistance angular impulse (N m s), 3
C_MU_D = 28        # combined dynamic friction coefficient
C_MU_S = 29        # combined static friction coefficient
C_E = 30           # combined restitution
C_ROLL = 31        # combined rolling friction (m)
C_VN0 = 32         # relative normal velocity before the solve (m/s), for restitution
C_MAX_N = 33       # largest normal impulse in the step (N s), for restitution
C_ADJ_SEP = 34     # separation at detection, for updating it from the bodies' motion (m)
C_SUM_N = 35       # normal impulse applied over the whole step (N s)
C_SUM_T = 36       # friction impulse applied over the whole step, world vector (N s), 3
CF_COLS = 39

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
