"""The bifilar pendulum: rig files, models of motion, identification, bodies and the other seeds.

Importing the package points numba's cache at the user's cache folder (:mod:`bifilar.jit`).
"""

from bifilar.jit import use_user_cache

use_user_cache()
