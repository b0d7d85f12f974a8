"""Test-suite configuration.

Hypothesis profiles: ``default`` (``make test``: bounded examples, no per-example deadline,
since a first call may include a JIT compile) and ``thorough`` (``make test-all``), chosen with
``HYPOTHESIS_PROFILE``.
"""

import os

from hypothesis import HealthCheck, settings

pytest_plugins = ["claim_verdicts"]  # the report's claim verdicts, from tests/claims

settings.register_profile("default", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", max_examples=500, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))
