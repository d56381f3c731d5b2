"""The stages of a world step, in order: the one list that the step, its profile and the docs follow.

Each stage is a compiled function over the step context (``pipeline/context.py``) in ``pipeline/step.py``;
the step of each collision-handling scheme calls them in this order (a scheme leaves out what it does
not use: the penalty scheme has no warm start of contacts and no restitution pass).  ``World.profile``
reports the time of each by these names.
"""

#: (name, what the stage does), in step order; the stages from ``integrate_velocities`` to
#: ``sum_impulses`` run once per sub-step.
STAGES = (
    ("aabbs", "bounding boxes of the bodies, grown by the speculative distance and their motion over the step"),
    ("broad_phase", "candidate pairs of overlapping boxes, in one canonical order whatever the method"),
    ("narrow_phase", "contact points of each pair at the poses the step began with (speculative ones too); a pair "
                     "that has hardly moved since last step keeps its points (the body-pair cache)"),
    ("time_of_impact", "impacts of an interval that began at a time of impact resolved; speculative contacts "
                       "that no motion reaches dropped; the earliest time of impact may end the interval"),
    ("match_and_wake", "warm start from last step's contacts by (bodies, shapes, feature); awake bodies "
                       "touching sleeping islands wake them"),
    ("prepare", "contact basis, effective masses and materials; the execution variant chosen once: one "
                "scalar pass, coloured bundles solved eight at a time, or regions on several threads; the "
                "joints' trees found (the joints without a loop, children first)"),
    ("integrate_velocities", "forces (gravity, user forces, springs; penalty springs in that scheme) to "
                             "velocities by the chosen integrator"),
    ("warm_start", "last sub-step's impulses of joints and contacts applied again; the joints' rows filled at "
                   "the sub-step's poses (the trees factored in the first sub-step; later ones reuse the "
                   "factors of the last relax)"),
    ("solve", "sequential impulses with soft position correction (overlap opened at no more than "
              "max_push_speed), iterated until no velocity changes more than the tolerance (the LCP scheme: "
              "all rows as one assembled LCP)"),
    ("integrate_positions", "velocities to poses; quaternions renormalised"),
    ("relax", "sequential impulses without position bias, removing the correction's velocity; the joints' "
              "rows filled and their trees factored at the new poses; overlap too deep for that and the "
              "joints' error pushed out by split impulses that move the poses, never the velocities (the "
              "trees' exactly, in the first pass and again after the last)"),
    ("sum_impulses", "the sub-step's impulses added to the step's totals"),
    ("restitution", "closing contacts bounce at -e times their approach speed"),
    ("store_impulses", "contacts at the friction cone slide in the next step; joints' forces recorded"),
    ("break_constraints", "springs, rods and cables over their breaking force snap"),
    ("islands_and_sleep", "islands of touching bodies; resting islands fall asleep; force accumulators "
                          "cleared"),
)
#: the stage names, in step order
STAGE_NAMES = tuple(name for name, _ in STAGES)
(ST_AABBS, ST_BROAD_PHASE, ST_NARROW_PHASE, ST_TIME_OF_IMPACT, ST_MATCH_AND_WAKE, ST_PREPARE,
 ST_INTEGRATE_VELOCITIES, ST_WARM_START, ST_SOLVE, ST_INTEGRATE_POSITIONS, ST_RELAX, ST_SUM_IMPULSES, ST_RESTITUTION,
 ST_STORE_IMPULSES, ST_BREAK_CONSTRAINTS, ST_ISLANDS_AND_SLEEP) = range(len(STAGES))
#: first stage of the sub-step loop and one past its last
SUBSTEP_STAGES = (ST_INTEGRATE_VELOCITIES, ST_SUM_IMPULSES + 1)


def describe():
    """The stages as indented text lines (the sub-step stages under a "for each sub-step" line)."""
    lines = []
    for k, (name, what) in enumerate(STAGES):
        if k == SUBSTEP_STAGES[0]:
            lines.append("for each sub-step of h = dt / substeps:")
        indent = "    " if SUBSTEP_STAGES[0] <= k < SUBSTEP_STAGES[1] else ""
        lines.append(f"{indent}{name:24s}{what}")
    return "\n".join(lines)
