#!/usr/bin/env bash
# Delete Numba's on-disk kernel cache of the package. Needed after editing a kernel that kernels in
# other files call: Numba does not notice that a callee in another file changed.
cd "$(dirname "$0")/.." && find marbellous -name '*.nbi' -delete -o -name '*.nbc' -delete
