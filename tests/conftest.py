"""Suite-wide: tests sharing a costly module fixture run on one xdist worker, so it is built once."""

import pytest

# fixture name -> xdist group; `--dist loadgroup` (pyproject's addopts) sends each group to one worker.
COSTLY_MODULE_FIXTURES = {
    "curl_run": "lab-curl-run",  # a whole 120-trial lab run of the adapting bot
    "planning": "planning-optimum",  # the minimum-torque-change optimisation
    "seeds": "replay-seeds",  # a search over 200 seeds
}


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        for fixture, group in COSTLY_MODULE_FIXTURES.items():
            if fixture in getattr(item, "fixturenames", ()):
                item.add_marker(pytest.mark.xdist_group(group))
