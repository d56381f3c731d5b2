"""Slots: the rows of a table handed out to objects, reused after removal, with revision numbers.

A table's rows are its slots.  ``allocate`` hands out the lowest free rows (so a world built the same way
has the same rows, and the step visits bodies in the same order), ``free`` returns them, and every row
counts its revision: the number of times it has been freed.  A handle remembers the row and the revision it
was given; once the row is freed (and perhaps reused) the revisions differ, and the handle knows it is
stale.

``end`` is one past the highest row in use: the step loops over ``range(end)`` and skips free rows, so its
cost follows what is alive now, not what was ever made (freeing the top rows lowers ``end``).
"""
import bisect

import numpy as np


class Slots:
    """The allocation state of one table's rows: which are in use, their revisions, and ``end``."""

    __slots__ = ("_free", "_end", "revision")

    def __init__(self):
        self._free = []          # free rows below end, ascending
        self._end = 0
        #: revision of each row (int64, grown with the table): how many times the row was freed
        self.revision = np.zeros(8, dtype=np.int64)

    @property
    def end(self):
        """One past the highest row in use."""
        return self._end

    @property
    def count(self):
        """Rows in use."""
        return self._end - len(self._free)

    def in_use(self, row):
        """True if ``row`` is allocated."""
        if not 0 <= row < self._end:
            return False
        k = bisect.bisect_left(self._free, row)
        return k == len(self._free) or self._free[k] != row

    def peek(self, n=1):
        """The first row of the ``n`` consecutive rows :meth:`allocate` would hand out (nothing changes)."""
        run = 0
        for k, row in enumerate(self._free):
            run = run + 1 if k > 0 and self._free[k - 1] == row - 1 else 1
            if run == n:
                return row - n + 1
        # the free rows that end the used range, extended past the end
        tail = 0
        while tail < len(self._free) and self._free[-1 - tail] == self._end - 1 - tail:
            tail += 1
        return self._end - min(tail, n)

    def allocate(self, n=1):
        """Take the lowest ``n`` consecutive free rows (past the end if no run of them is free); returns the
        first.  The caller grows the table to ``end`` rows."""
        first = self.peek(n)
        for row in range(first, first + n):
            k = bisect.bisect_left(self._free, row)
            if k < len(self._free) and self._free[k] == row:
                del self._free[k]
        self._end = max(self._end, first + n)
        self._grow_revisions(self._end)
        return first

    def free(self, first, n=1):
        """Give back rows ``first .. first + n - 1``: their revisions advance, and free rows at the top lower
        ``end``."""
        for row in range(first, first + n):
            if not self.in_use(row):
                raise ValueError(f"row {row} is not in use")
            self.revision[row] += 1
            bisect.insort(self._free, row)
        while self._free and self._free[-1] == self._end - 1:
            self._free.pop()
            self._end -= 1

    def state(self):
        """``(end, free rows, revisions)`` as plain arrays, for a snapshot."""
        return self._end, np.array(self._free, dtype=np.int64), self.revision[:self._end].copy()

    def set_state(self, end, free, revision):
        """Return to a :meth:`state` (already validated by the caller).  A row in use now that the state
        has free gets a new revision, so that no handle of today's object can match a later one."""
        in_use_now = [row for row in range(self._end) if self.in_use(row)]
        self._grow_revisions(int(end))
        self._end = int(end)
        self._free = [int(r) for r in free]
        self.revision[:self._end] = np.maximum(self.revision[:self._end], revision)
        for row in in_use_now:
            if not self.in_use(row):
                self.revision[row] += 1

    def _grow_revisions(self, n):
        if self.revision.shape[0] < n:
            grown = np.zeros(max(n, 2 * self.revision.shape[0]), dtype=np.int64)
            grown[:self.revision.shape[0]] = self.revision
            self.revision = grown
