#!/usr/bin/env python3
"""Writes examples/walkthrough/scan.x3p: a raw profilometer scan LIKE a measured one.

No public measured scan can be shipped with strata (the instrument files of the
SurfaceTopography repository are Git LFS pointers), so the walkthrough
(docs/guide/walkthrough.md) starts from this synthetic one, made to carry what a raw
scan carries and a generated surface does not:

- non-periodic and rectangular: 256 × 192 points, 2 µm pixels (512 × 384 µm), cut
  from the middle of a larger random field, so its edges do not meet;
- self-affine roughness: Hurst exponent H = 0.8 (C(q) ∝ q^-2(1+H)) from a roll-off
  wavelength of 250 µm down to 10 µm, where the instrument's lateral resolution
  (a Gaussian transfer function of width 3 µm) damps it; RMS 0.6 µm;
- a stage tilt that dominates the raw heights: slopes 1.0e-2 (x) and -0.4e-2 (y),
  plus an arbitrary height offset of 12 µm;
- instrument noise: white, 5 nm RMS;
- eleven dropouts (missing points, invalid in bindata/valid.bin and NaN in the data,
  as instruments write them): eight single points and a 1 × 3 streak; and one spike
  (+3 µm on one point, a glitch).

The file is ISO 25178-72 (.x3p): main.xml, bindata/data.bin (float32, little-endian,
x fastest), bindata/valid.bin (one bit per point, 1 = valid), md5checksum.hex. The
zip entries carry a fixed date, so the output is a function of this script and
numpy's PCG64 stream for the seed (numpy >= 1.17).

Run from the repository root:  python3 tools/walkthrough_scan.py [OUT]
(default OUT: examples/walkthrough/scan.x3p). Needs numpy.
"""

import hashlib
import io
import sys
import zipfile

import numpy as np

SEED = 38
NX, NY = 256, 192          # points along x (SizeX) and y (SizeY)
DX = 2e-6                  # pixel size (m), both axes
H = 0.8                    # Hurst exponent
ROLLOFF = 250e-6           # roll-off wavelength (m): flat PSD above it
RESOLUTION = 3e-6          # instrument transfer: Gaussian exp(-(q r)^2 / 2), r = this / 2
RMS = 0.6e-6               # roughness RMS (m), before noise
SLOPE_X, SLOPE_Y = 1.0e-2, -0.4e-2
OFFSET = 12e-6             # z offset of the instrument (m)
NOISE = 5e-9               # white noise RMS (m)
DROPOUTS = [(17, 40), (63, 150), (100, 11), (131, 97), (170, 170), (201, 66),
            (230, 128), (44, 181)]
STREAK = [(150, 30), (150, 31), (150, 32)]
SPIKE = ((88, 120), 3e-6)


def roughness(rng):
    """Self-affine field on a 2× larger periodic grid, cut to NX × NY (x first)."""
    m0, m1 = 2 * NX, 2 * NY
    qx = 2 * np.pi * np.fft.fftfreq(m0, DX)
    qy = 2 * np.pi * np.fft.rfftfreq(m1, DX)
    q = np.hypot(qx[:, None], qy[None, :])
    qr = 2 * np.pi / ROLLOFF
    c = np.where(q < qr, qr, q) ** (-2 * (1 + H))
    c *= np.exp(-(q * RESOLUTION / 2) ** 2)
    c[0, 0] = 0.0
    phase = rng.normal(size=q.shape) + 1j * rng.normal(size=q.shape)
    z = np.fft.irfft2(np.sqrt(c) * phase, s=(m0, m1))
    z = z[m0 // 4: m0 // 4 + NX, m1 // 4: m1 // 4 + NY]
    return RMS * (z - z.mean()) / z.std()


def scan():
    """Heights (m, x first) with NaN at the dropouts, and the validity mask."""
    rng = np.random.default_rng(SEED)
    z = roughness(rng)
    x = DX * np.arange(NX)[:, None]
    y = DX * np.arange(NY)[None, :]
    z = z + OFFSET + SLOPE_X * x + SLOPE_Y * y + NOISE * rng.normal(size=(NX, NY))
    (si, sj), sh = SPIKE
    z[si, sj] += sh
    valid = np.ones((NX, NY), dtype=bool)
    for i, j in DROPOUTS + STREAK:
        valid[i, j] = False
        z[i, j] = np.nan
    return z, valid


MAIN = """<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:schemaLocation="http://www.opengps.eu/2008/ISO5436_2 http://www.opengps.eu/2008/ISO5436_2/ISO5436_2.xsd">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx:e}</Increment><Offset>0</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx:e}</Increment><Offset>0</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>F</DataType><Increment>1</Increment><Offset>0</Offset></CZ>
    </Axes>
  </Record1>
  <Record2>
    <Date>2025-01-01T00:00:00Z</Date>
    <Instrument>
      <Manufacturer>strata</Manufacturer>
      <Model>synthetic profilometer (tools/walkthrough_scan.py)</Model>
      <Serial>not available</Serial>
      <Version>1</Version>
    </Instrument>
    <ProbingSystem><Type>NonContacting</Type><Identification>synthetic</Identification></ProbingSystem>
    <Comment>Synthetic raw scan for docs/guide/walkthrough.md: self-affine H = 0.8, RMS 0.6 um, stage tilt 1e-2 / -0.4e-2, 5 nm noise, 11 dropouts, 1 spike</Comment>
  </Record2>
  <Record3>
    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink>
      <PointDataLink>bindata/data.bin</PointDataLink>
      <MD5ChecksumPointData>{data_md5}</MD5ChecksumPointData>
      <ValidPointsLink>bindata/valid.bin</ValidPointsLink>
      <MD5ChecksumValidPoints>{valid_md5}</MD5ChecksumValidPoints>
    </DataLink>
  </Record3>
  <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>
"""


def x3p(z, valid):
    """The .x3p container's bytes: point (i, j) at index j·SizeX + i."""
    data = z.T.astype("<f4").tobytes()
    bits = np.packbits(valid.T.ravel(), bitorder="little").tobytes()
    main = MAIN.format(dx=DX, nx=NX, ny=NY,
                       data_md5=hashlib.md5(data).hexdigest(),
                       valid_md5=hashlib.md5(bits).hexdigest()).encode()
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, payload in [("main.xml", main), ("bindata/data.bin", data),
                              ("bindata/valid.bin", bits),
                              ("md5checksum.hex",
                               f"{hashlib.md5(main).hexdigest()} *main.xml\n".encode())]:
            info = zipfile.ZipInfo(name, date_time=(2025, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, payload)
    return out.getvalue()


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "examples/walkthrough/scan.x3p"
    z, valid = scan()
    with open(path, "wb") as f:
        f.write(x3p(z, valid))
    ok = np.isfinite(z)
    print(f"{path}: {NX}×{NY} points, {DX:e} m pixels, {int((~valid).sum())} dropouts; "
          f"raw RMS {np.nanstd(z):.3e} m")


if __name__ == "__main__":
    main()
