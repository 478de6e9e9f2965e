"""The pose kernels as one-shot work calls them: ``PK``, compiled only once they loop.

:mod:`bifilar.rig.pose_kernel` holds the numba kernels themselves (called as such from other compiled
kernels); ``PK`` wraps that module in :class:`bifilar.jit.LoopKernels`, so that one rig's rest pose and
modes (statics, elastic statics, modes) run in plain Python until the kernels are cached or loop. It is a
module of its own so that statics and elastic statics both import it without importing each other.
"""

from bifilar.jit import LoopKernels
from bifilar.rig import pose_kernel

PK = LoopKernels(pose_kernel, "the pose kernels", seconds="10-30")
