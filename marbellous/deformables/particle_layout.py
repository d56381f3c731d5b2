"""Column layout of the particle tables: the one place where a particle or edge column gets its number.

Particles live in ``pf`` (float64, capacity x ``PF_COLS``) and ``pi`` (int64, capacity x ``PI_COLS``); the
particles of one ``Particles`` set are contiguous rows, listed in the set table ``sets`` (int64, one row per
set).  The edges of the networks (springs, rods, cables between two particles) live in ``ef`` / ``ei``.
"""

# --- particles, float table pf ---------------------------------------------------------------------------
P_POS = 0            # position (m), 3
P_VEL = 3            # velocity (m/s), 3
P_PREV = 6           # position at the start of the sub-step (m), 3 (scratch of the step)
P_INV_MASS = 9       # 1/m (1/kg); 0 while pinned to the world
P_MASS = 10          # m (kg)
P_RADIUS = 11        # radius (m)
P_FORCE = 12         # user force (N), 3; cleared after each step
P_FRICTION = 15      # dynamic (sliding) Coulomb coefficient
P_STATIC_FRICTION = 16  # static (sticking) Coulomb coefficient
P_RESTITUTION = 17   # coefficient of restitution in [0, 1]
P_DAMPING = 18       # rate (1/s) at which velocity relative to the set's mean velocity decays
P_PIN = 19           # pinned: the world point (m), or the point in the pinning body's frame (m), 3
P_VEL0 = 22          # velocity at the start of the sub-step (m/s), 3 (scratch of the step)
P_REST = 25          # a cloth vertex's place in the cloth's rest shape (m), 3 (its edges' and bends' rest state)
P_CONTACT = 28       # a soft body's node: the unit normal of its contact in the last sub-step, 3; zero: none
P_SUPPORT = 31       # a soft body's node: the normal impulse (N s) its contact gave in the last implicit step
PF_COLS = 32

# --- particles, int table pi ---------------------------------------------------------------------------------
P_SET = 0            # row of the particle's set in the set table
P_FLAGS = 1          # PP_* bits
P_PIN_BODY = 2       # body row the particle is pinned to (-1: the world, when PP_PINNED)
P_CLOTH = 3          # row of the particle's cloth in the cloth table (a cloth vertex); -1: not a cloth's
PI_COLS = 4

PP_PINNED = 1        # held at P_PIN (in the world, or on body P_PIN_BODY)
PP_COLLIDE = 2       # collides with the other particles that carry this bit (collide_particles)
PP_SOFT = 4          # a node of a soft body: the soft bodies' implicit step gives its velocity (soft_step.py)

# --- particle sets, int table sets -----------------------------------------------------------------------
SET_START = 0        # first particle row
SET_COUNT = 1        # number of particles
SET_SERIAL = 2       # the set's serial number (a handle's identity, kept by snapshots)
SETS_COLS = 3

# --- network edges, float table ef and int table ei -------------------------------------------------------
E_REST = 0           # rest length (spring), length (rod), largest length (cable) (m)
E_COMPLIANCE = 1     # 1/k (m/N) of a spring; 0 for rods and cables
E_DAMPING = 2        # damping coefficient (N s/m) along the edge
E_BREAKING = 3       # breaking tension (N); inf: unbreakable
E_FORCE = 4          # tension over the last step, its sub-steps' mean (N; > 0 pulls the ends together)
E_TEAR = 5           # length (m) past which the edge tears at the step's end (a cloth's tear_strain); inf: never
E_LAMBDA = 6         # the sub-step's Lagrange multiplier so far, summed over its passes (scratch of the step)
EF_COLS = 7

E_A = 0              # particle row of one end
E_B = 1              # particle row of the other end
E_KIND = 2           # EK_* below
E_FLAGS = 3          # EB_* bits
E_NETWORK = 4        # serial number of the network the edge belongs to
EI_COLS = 5

EK_SPRING = 0
EK_ROD = 1
EK_CABLE = 2
#: the kinds by their names in ``World.add_network``
EDGE_KINDS = {"spring": EK_SPRING, "rod": EK_ROD, "cable": EK_CABLE}

EB_BROKEN = 1

# --- cloth: triangles (int table tri), bends (float table bend_f, int table bend_i), cloths (float table cl) --
T_A = 0              # particle rows of the triangle's corners, 3, counter-clockwise seen from its front
T_CLOTH = 3          # row of the triangle's cloth in the cloth table
T_BORDER = 4         # bit k set: the triangle's edge opposite its corner k is on the cloth's border (no other
#                      triangle has it)
TRI_COLS = 5

BN_ANGLE = 0         # rest dihedral angle (rad), signed
BN_COMPLIANCE = 1    # 1 / bending stiffness of the hinge (1 / (N m per rad^2))
BENDF_COLS = 2
BN_A = 0             # particle rows: the hinge's edge (2), then the far corner of each of its triangles (2)
BENDI_COLS = 4

CL_THICKNESS = 0     # the cloth's thickness (m): its triangles keep points this far plus their radius away
CL_SELF = 1          # 1: the cloth's own vertices collide with its triangles (self_collision)
CL_COLS = 2

# --- soft bodies: tetrahedral elements, float table tf and int table ti ------------------------------------------
S_DM_INV = 0         # Dm^-1, Dm = [X1 - X0, X2 - X0, X3 - X0] the rest edges (1/m), 9, row-major
S_VOLUME = 9         # rest volume V (m^3)
S_LAMBDA = 10        # Lame's first parameter lambda (Pa)
S_MU = 11            # shear modulus mu (Pa)
S_DAMPING = 12       # stiffness-proportional (Rayleigh) damping beta (s)
S_QUAT = 13          # the element's rotation from its rest shape (w, x, y, z), 4: the last step's
TF_COLS = 17

S_NODES = 0          # particle rows of the four corners, 4 (X0 .. X3, positive volume)
S_SOFT = 4           # serial number of the soft body the element belongs to
TI_COLS = 5

# --- the contacts of a sub-step, float table kf and int table ki (scratch of the step) ------------------------
K_NORMAL = 0         # unit normal from the other side to the particle, 3
K_POINT = 3          # the point on the other side's surface (m), 3
K_DEPTH = 6          # the overlap the position pass removed (m)
K_VN0 = 7            # relative normal velocity before the sub-step (m/s; < 0 approaching)
K_MU = 8             # dynamic friction coefficient of the pair
K_E = 9              # restitution of the pair
K_STUCK = 10         # 1: static friction held the contact in the position pass
KF_COLS = 11

K_PARTICLE = 0       # the particle's row
K_OTHER = 1          # the other side: a body row, or a particle row
K_KIND = 2           # KK_* below
KI_COLS = 3

KK_BODY = 0
KK_PARTICLE = 1

# --- the pushes of a sub-step's cloth contacts with cloth (points on triangles, edges on edges), float table
# lf and int table li (scratch of the step, for the whole-cloth solve, layer_contacts.py) ------------------------
L_NORMAL = 0         # the unit normal the push was along, 3
L_WEIGHT = 3         # each corner's weight in the contact's distance n . sum_j c_j x_j, 4
L_PUSH = 7           # the positional impulse (kg m) the position pass gave along n
L_TARGET = 8         # the distance (m) it pushed the contact out to
LF_COLS = 9

L_CORNER = 0         # the four corners' particle rows (-1: none), 4
LI_COLS = 4

# --- the step's parameters, float array params (one per call) ----------------------------------------------
Q_DT = 0             # the step (s)
Q_GRAVITY = 1        # 3 (m/s^2)
Q_SUBSTEPS = 4       # sub-steps per step (a whole number)
Q_STRETCH_PASSES = 5  # local-global passes of the cloths' stretch per sub-step (stretch_solve.py); 0: none
Q_LOADS = 6          # 1: the sub-steps follow the bodies' loads, the candidates say which lie on particles
                     # (load_substeps.py); 0: the sub-steps are set
Q_LEN = 7
