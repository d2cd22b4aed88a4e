"""Makes the contact.engineering container fixture with SurfaceTopography (tests/it/container.rs).

Run from this directory: python make.py (SurfaceTopography 1.x, numpy). Writes container.zip
(SurfaceContainer.to_zip: meta.yml, index.json, topography0.nc, topography1.nc, README.txt) and
the same heights as .npy in their units (x first), for the equality test.
"""

import numpy as np
from SurfaceTopography import Topography
from SurfaceTopography.Container.SurfaceContainer import InMemorySurfaceContainer

rng = np.random.default_rng(36)
a = rng.normal(size=(32, 32))                    # µm, periodic 50 × 50 µm
b = rng.normal(size=(48, 32)) * 400 + np.linspace(0, 800, 48)[:, None]   # nm, 3000 × 2000 nm
ta = Topography(a, (50.0, 50.0), unit="µm", periodic=True, info={"name": "periodic-um"})
tb = Topography(b, (3000.0, 2000.0), unit="nm", periodic=False, info={"name": "scan-nm"})
InMemorySurfaceContainer([ta, tb]).to_zip("container.zip")
np.save("periodic-um.npy", a)
np.save("scan-nm.npy", b)
