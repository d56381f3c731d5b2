"""The adaptive step loops: a step of ``dt`` taken in several intervals (the lecture's "Time Handling").

Every interval is one run of the compiled step (``pipeline/step.py``) with ``PF_DT`` set to its length;
its time-of-impact stage (``pipeline/impacts.py``) resolves the impacts an interval begins with, and may
stop before solving anything (``SPLIT``) to ask for a shorter interval that ends at the earliest impact.

- **fixed with continuous collision** (``run_span``): the step is tried whole; at a SPLIT it is taken up to
  the impact's time ``t_1`` (never less than ``dt / 2**max_halvings``), the next interval begins by
  resolving that impact and goes on to the next, until ``dt`` is used up.
- **conservative**: the same loop, with every body's new contacts ending an interval (TOI_ALL): each
  interval advances to a conservative lower bound of the next time a new contact begins.
- **retroactive** (``retroactive_span``): the state is saved, the interval taken, and the contacts at its end
  detected (a detection pass: the collide stages only).  If a pair of shapes then overlaps deeper than
  ``max_penetration`` and deeper than it did when the interval began, the state is restored and the
  interval taken as two halves, each of which may halve again, down to ``dt / 2**max_halvings``.

The world's clock advances by exactly ``dt``: it is set to ``t0 + dt`` when the step ends, whatever the sum
of the intervals rounds to.  The contacts reported afterwards are the last interval's, with the impulses
of every interval (and of the impacts resolved at their starts) added up by contact (bodies, shapes,
feature); impulses of contacts gone by the last interval are not reported.

The loops work on a world's state (``state/world_state.py``: its tables and ``step``) and a function that
writes the step's parameters for an interval; they import nothing above the pipeline.
"""
import math

import numpy as np

from ..state import layout as L
from .contact_events import approach_table
from .impacts import DETECTED, SPLIT

#: the columns of a contact that identify it from interval to interval
_KEY_COLUMNS = [L.C_BODY_A, L.C_BODY_B, L.C_SHAPE_A, L.C_SHAPE_B, L.C_FEATURE]


class StepLoop:
    """The intervals of one world step and what they report.

    ``state``: the world's ``WorldState``; ``write_interval(tau)``: writes the step parameters for an interval
    of ``tau`` seconds (``PF_DT`` and what depends on it).  After :meth:`finish`, ``steps``, ``halvings``,
    ``toi_events`` and ``smallest_dt`` (s) describe the step (``reports.StepReport``).
    """

    def __init__(self, state, write_interval, dt, min_interval):
        self.state = state
        self.write_interval = write_interval
        self.dt = dt
        self.min_interval = min_interval
        self.t0 = float(state.ws[L.W_TIME])
        self.steps = 0
        self.halvings = 0
        self.toi_events = 0
        self.smallest_dt = math.inf
        self._keys = []            # each completed interval's contact keys (n, 5) and impulses (n, 4)
        self._sums = []
        self._impacts = []         # impacts resolved by attempts that stopped with SPLIT: keys and impulses
        self._resolved = False     # some completed interval began by resolving impacts
        self.rewritten = False     # the parameters were written for an interval shorter than the step
        n = state.n_cached         # the contacts the step begins with, and each interval's approach speeds
        self.start_contacts = (state.cache_f[:n].copy(), state.cache_i[:n].copy())
        self._approach = []
        self._impact_approach = []

    # --- intervals ------------------------------------------------------------------------------------------
    def run_span(self, span, first_status=None):
        """Cover ``span`` seconds with intervals that end at impacts (when the step's mode asks for it).
        ``first_status``: the status of a first attempt over the whole span already made (SPLIT)."""
        st = self.state
        pi = st.params_i
        split = pi[L.PI_TOI_SPLIT]
        t = 0.0
        while True:
            rest = span - t
            if first_status is None:
                self._set_interval(rest)
                status = st.step()
            else:
                status, first_status = first_status, None
            tau = rest
            if status == SPLIT:
                self._note_impacts(False)
                tau = float(st.time_f[L.T_LIMIT])
                if rest - tau < self.min_interval:      # no sliver shorter than the shortest interval
                    tau = rest
                else:
                    self.toi_events += 1
                self._set_interval(tau)
                pi[L.PI_TOI_SPLIT] = 0
                status = st.step()
                pi[L.PI_TOI_SPLIT] = split
            self._note_interval(tau)
            if tau >= rest:
                return
            t += tau

    def _set_interval(self, tau):
        """The step's parameters for an interval of ``tau`` seconds (written only when it changes:
        ``rewritten`` tells the world its parameters no longer hold the whole step's)."""
        if self.state.params_f[L.PF_DT] != tau:
            self.write_interval(tau)
            self.rewritten = True

    def retroactive_span(self, span, level, max_halvings, max_penetration, start):
        """Take ``span`` seconds (a half of a half ... ``level`` times), undone and halved while it ends with
        a new overlap deeper than ``max_penetration`` (m).  ``start``: the deep overlaps when it begins
        (:meth:`overlaps`), None if not known yet (they are measured only when the end has a deep one).
        Returns the deep overlaps at its end."""
        saved = self._save()
        marks = self._marks()
        self.run_span(span)
        end = self.overlaps(max_penetration)
        if not end or level >= max_halvings:
            return end
        self._restore(saved)
        self._rollback(marks)
        if start is None:
            start = self.overlaps(max_penetration)
        # (a pair missing from ``start`` was at most max_penetration deep: shallower than it is now)
        if not any(d > start.get(k, 0.0) for k, d in end.items()):
            # deep already when the interval began (bodies placed in one another): not the step's doing
            self.run_span(span)
            return end
        self.halvings += 1
        half = 0.5 * span
        middle = self.retroactive_span(half, level + 1, max_halvings, max_penetration, start)
        return self.retroactive_span(span - half, level + 1, max_halvings, max_penetration, middle)

    def overlaps(self, floor):
        """The deepest overlap (m) of each pair of shapes ``(shape_a, shape_b)`` that overlaps deeper than
        ``floor`` (m) at the current poses (sensors left out), by a detection pass of the step: the collide
        stages with no prediction."""
        st = self.state
        pf, pi = st.params_f, st.params_i
        saved = pf[L.PF_SPECULATIVE], pf[L.PF_SWEEP]
        pf[L.PF_SPECULATIVE] = 0.0
        pf[L.PF_SWEEP] = 0.0
        pi[L.PI_DETECT] = 1
        try:
            status = st.step()
        finally:
            pf[L.PF_SPECULATIVE], pf[L.PF_SWEEP] = saved
            pi[L.PI_DETECT] = 0
        assert status == DETECTED
        n = int(st.stats[L.STAT_CONTACTS])
        cf, ci = st.contact_table_f(False)[:n], st.contact_table_i(False)[:n]
        deep = ((ci[:, L.C_FLAGS] & L.CP_SENSOR) == 0) & (cf[:, L.C_DEPTH] > floor)
        out = {}
        for sa, sb, d in zip(ci[deep, L.C_SHAPE_A].tolist(), ci[deep, L.C_SHAPE_B].tolist(),
                             cf[deep, L.C_DEPTH].tolist()):
            out[(sa, sb)] = max(d, out.get((sa, sb), d))
        return out

    def finish(self):
        """End the step: the clock at exactly ``t0 + dt``, and the last interval's contacts carrying the
        impulses of the whole step."""
        st = self.state
        st.ws[L.W_TIME] = self.t0 + self.dt
        n = st.n_cached
        if n == 0 or (len(self._keys) <= 1 and not self._impacts and not self._resolved):
            return
        cf = st.cache_f
        keys = self._keys + [k for k, _ in self._impacts]
        sums = self._sums + [s for _, s in self._impacts]
        last = self._keys[-1]
        every = np.concatenate(keys)
        _, inverse = np.unique(np.concatenate([last, every]), axis=0, return_inverse=True)
        inverse = inverse.ravel()
        row_of = np.full(inverse.max() + 1, -1, dtype=np.int64)
        row_of[inverse[:n]] = np.arange(n)
        target = row_of[inverse[n:]]
        found = target >= 0
        totals = np.zeros((n, 4))
        np.add.at(totals, target[found], np.concatenate(sums)[found])
        cf[:n, L.C_SUM_N] = totals[:, 0]
        cf[:n, L.C_SUM_T:L.C_SUM_T + 3] = totals[:, 1:]

    # --- bookkeeping --------------------------------------------------------------------------------------------
    def _note_interval(self, tau):
        """Count a completed interval of ``tau`` seconds and keep its contacts' keys and impulses."""
        self.steps += 1
        self.smallest_dt = min(self.smallest_dt, tau)
        st = self.state
        n = st.n_cached
        cf, ci = st.cache_f[:n], st.cache_i[:n]
        sums = np.empty((n, 4))
        sums[:, 0] = cf[:, L.C_SUM_N]
        sums[:, 1:] = cf[:, L.C_SUM_T:L.C_SUM_T + 3]
        approach = approach_table(cf, ci)
        if st.time_f[L.T_RESOLVED] > 0:
            sums += st.impact_f[:n, :L.IMP_SUMS]
            np.maximum(approach[:, 2], st.impact_f[:n, L.IMP_APPROACH], out=approach[:, 2])
            self._resolved = True
        self._keys.append(ci[:, _KEY_COLUMNS].copy())
        self._sums.append(sums)
        self._approach.append(approach)

    def _note_impacts(self, cached):
        """Keep the impulses of impacts an attempt resolved before it stopped with SPLIT (its contacts are in
        the table the step fills, not yet the cache)."""
        st = self.state
        if st.time_f[L.T_RESOLVED] > 0:
            n = int(st.stats[L.STAT_CONTACTS])
            ci = st.contact_table_i(cached)[:n]
            self._impacts.append((ci[:, _KEY_COLUMNS].copy(), st.impact_f[:n, :L.IMP_SUMS].copy()))
            approach = approach_table(st.contact_table_f(cached)[:n], ci)
            approach[:, 2] = st.impact_f[:n, L.IMP_APPROACH]
            self._impact_approach.append(approach)

    def approach_speeds(self):
        """Every completed interval's contacts, and the impacts resolved before an attempt split, as rows
        ``(body a, body b, approach speed (m/s))``."""
        return np.concatenate([np.zeros((0, 3))] + self._approach + self._impact_approach)

    def _marks(self):
        return (len(self._keys), len(self._impacts), self.steps, self.toi_events, self.smallest_dt,
                self._resolved)

    def _rollback(self, marks):
        """Forget what the intervals since ``marks`` (:meth:`_marks`) reported (they were undone)."""
        nk, ni, self.steps, self.toi_events, self.smallest_dt, self._resolved = marks
        del self._keys[nk:]
        del self._sums[nk:]
        del self._approach[nk:]
        del self._impacts[ni:]
        del self._impact_approach[ni:]

    def _save(self):
        """The mutable rows of the state (bodies, constraints, clock, contact cache): a light snapshot."""
        st = self.state
        nb, nk, n = st.bodies.end, st.constraints.end, st.n_cached
        return (st.bf[:nb].copy(), st.bi[:nb].copy(), st.kf[:nk].copy(), st.ki[:nk].copy(), st.ws.copy(),
                st.cache_f[:n].copy(), st.cache_i[:n].copy())

    def _restore(self, saved):
        """Write back the rows :meth:`_save` took (nothing is added or removed within a step)."""
        st = self.state
        bf, bi, kf, ki, ws, cf, ci = saved
        st.bf[:bf.shape[0]] = bf
        st.bi[:bi.shape[0]] = bi
        st.kf[:kf.shape[0]] = kf
        st.ki[:ki.shape[0]] = ki
        st.ws[:] = ws
        n = cf.shape[0]
        if st.cache_f.shape[0] < n:
            st.grow_contacts(n)
        st.cache_f[:n] = cf
        st.cache_i[:n] = ci
        st.stats[L.STAT_CACHED] = n
