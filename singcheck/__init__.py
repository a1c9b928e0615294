"""singcheck: certify that a parallel robot's trajectory avoids parallel singularities.

The method is Jha, Chablat, Rouillier, Moroz, "An algebraic method to check the
singularity-free paths for parallel robots" (IDETC 2015).

The public API (see :mod:`singcheck.api`)::

    import singcheck
    robot = singcheck.load_robot("robots/orthoglide.yaml", backend="auto")
    traj = singcheck.load_trajectory("trajectories/heart1.yaml", robot)
    report = singcheck.check(robot, traj)   # report.verdict, .candidates, .working_modes
    report.to_dict()                        # the JSON schema's trajectory object

The package is cut by pipeline stage, each importing only the stages below it:
``algebra`` → ``spec`` → ``model`` → ``elimination`` → ``roots`` → ``certify`` →
``spaces`` → ``report`` → ``api`` → ``cli``; ``errors``, ``budget``, ``atomic`` and
``version`` are
foundation modules every stage may use.  The API is loaded on first use, so that
``import singcheck`` stays cheap.
"""

from singcheck.version import __version__

__all__ = ["Report", "Robot", "check", "check_batch", "check_safely", "load_robot",
           "load_trajectory", "load_trajectories", "robot_from_spec", "__version__"]


def __getattr__(name: str):
    if name in __all__:
        from singcheck import api

        return getattr(api, name)
    raise AttributeError(f"module 'singcheck' has no attribute {name!r}")
