"""Deterministic lubricating flow over a rough wall: the torque a rough lining on smooth steel transmits.

A second method for the Patir-Cheng shear factors of Cui 2019 Eq. 5-9 (physics/shear.py): the film
between a smooth wall moving at U (the steel separator) and a fixed rough wall (the friction lining,
heights delta, gap h = h0 - delta) is solved deterministically with the Reynolds equation, and the
mean stresses on both walls are averaged.

Geometry and signs
------------------
x is the sliding direction, z across the film, the rough wall's surface is z = delta(x, y), the
smooth wall z = h0 moves at +U. Per point the velocity is the Couette-Poiseuille profile
u(z) = U (z - delta)/h + p_x (z - delta)(z - h0)/(2 eta), the flux q = U h/2 - h^3 grad(p)/(12 eta),
and mass conservation gives div(h^3 grad p / (12 eta)) = (U/2) dh/dx with periodic p.

* ``smooth_drag`` = eta du/dz at the smooth wall = eta U/h + (h/2) p_x: the force per area the oil
  exerts on the smooth wall against its motion (positive).
* ``rough_viscous`` = eta du/dz at the rough wall = eta U/h - (h/2) p_x: the viscous force per area on
  the rough wall in +x.
* ``form_drag`` = p d(delta)/dx = -p dh/dx: the x-component of the pressure on the rough wall's
  flanks per projected area, in +x (the solid's outward normal is (-delta_x, -delta_y, 1)).

All are means over the nominal area. The film's x-momentum balance makes rough_viscous + form_drag =
smooth_drag (mean(-p h_x) = mean(h p_x) for periodic p): the transmitted stress is the smooth wall's
drag, and smooth_drag = Couette + form_drag / 2, rough_viscous = Couette - form_drag / 2. The form
drag is a dissipation, mean(h p_x) = mean(h^3 |grad p|^2) / (6 eta U) >= 0, so a rough wall on a
smooth one always transmits *more* than its Couette shear.

Contact lines
-------------
Where asperities touch the smooth wall (h <= 0) no oil passes. Next to such a spot, with
h = |grad h| n at a distance n, zero flux into the spot needs p_n = 6 eta U_n / h^2: the pressure
grows like 1/h, and (h/2) p_x and p h_x like 1/h, as the Couette shear eta U/h does. All three are
log-divergent; Patir-Cheng's phi_f cuts the Couette shear below the gap 3 eps* sigma (Cui 2019 after
Eq. 6), and this module cuts flow and shear at the same gap. By Rice's formula for the length of
contact lines, the transmitted stress then grows like 2.5 phi(H) ln(1/cutoff) eta U / sigma
(Couette phi(H), pressure flow 1.5 phi(H); phi the normal density): at H = 1 about 1.5 in
phi_T per decade of the cut-off, at H = 3 about 0.08. The pressure varies on cutoff / |grad delta|
~ 0.007 lambda there, finer than a practical grid; the transmitted stress is therefore evaluated from
the depth-averaged velocity ubar = q / h, which stays bounded (-> (U/2)(1 - n_x^2), n the contact
line's normal): eta (4 U - 6 ubar_x) / h on the smooth wall, converged within ~2 %
at 32 cells per lambda.

Units: SI for the 1D functions; the 2D solver works in units of sigma (heights), the correlation
length lambda (x, y), eta U lambda / sigma^2 (pressure) and eta U / sigma (stresses); Reynolds
lubrication is invariant under x, y -> c x, c y, so its stresses do not depend on lambda.
"""

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.sparse.linalg import spsolve

from clutchocp.physics.roughness import average_gap

# Cui 2019 after Eq. 6: eps* = 1/300 of 3 sigma; below this local gap the oil carries no shear
SHEAR_CUTOFF_GAP = 3.0 / 300.0          # [sigma]


# ----------------------------------------------------------------------------------- 1D, exact


@dataclass(frozen=True)
class WallStresses:
    """Mean stresses of a film over a rough wall (see the module docstring for signs).

    Attributes
    ----------
    smooth_drag : float
        Drag on the smooth moving wall (= transmitted stress) [Pa, or the unit of the call].
    rough_viscous : float
        Viscous shear on the rough fixed wall, in the sliding direction [same unit].
    form_drag : float
        Pressure force on the rough wall's flanks per nominal area, in the sliding direction [same unit].
    couette : float
        Mean Couette part eta U / h [same unit].
    """

    smooth_drag: float
    rough_viscous: float
    form_drag: float
    couette: float


def periodic_wall_flow_1d(gap, speed=1.0, eta=1.0):
    """Exact stresses of the film over a 1D periodic rough wall (gap h(x) > 0, uniform samples).

    Per x the Couette-Poiseuille profile holds, the flux q is constant and the pressure periodic:
    p_x = 6 eta U / h^2 - 12 eta q / h^3 with mean(p_x) = 0 gives q = (U/2) E[1/h^2] / E[1/h^3].
    Then, with I_n = E[1/h^n] (means over one period),
    smooth_drag = eta U (4 I_1 - 3 I_2^2 / I_3), rough_viscous = eta U (3 I_2^2 / I_3 - 2 I_1),
    form_drag = mean(h p_x) = 6 eta U (I_1 - I_2^2 / I_3), couette = eta U I_1.

    Parameters
    ----------
    gap : array_like
        Local gap h at uniformly spaced points over one period (endpoint excluded) [m]; all > 0.
        The means are trapezoidal sums, spectrally accurate for a smooth periodic h.
    speed : float
        Sliding speed U of the smooth wall [m/s].
    eta : float
        Dynamic viscosity [Pa s].

    Returns
    -------
    WallStresses
        Mean stresses [Pa].
    """
    h = np.asarray(gap, dtype=float)
    if h.ndim != 1 or h.size < 2 or not np.all(h > 0):
        raise ValueError("gap must be a 1D array of at least 2 positive values")
    i1, i2, i3 = np.mean(1 / h), np.mean(h**-2), np.mean(h**-3)
    ratio = i2 * i2 / i3
    scale = eta * speed
    return WallStresses(smooth_drag=scale * (4 * i1 - 3 * ratio),
                        rough_viscous=scale * (3 * ratio - 2 * i1),
                        form_drag=6 * scale * (i1 - ratio),
                        couette=scale * i1)


def cosine_wall_closed_form(eps):
    """Closed-form stresses of the film over the wall h = h0 (1 + eps cos x), in units of eta U E[1/h].

    With E[1/h] = (1 - eps^2)^(-1/2) / h0, E[1/h^2] = (1 - eps^2)^(-3/2) / h0^2 and
    E[1/h^3] = (1 + eps^2/2)(1 - eps^2)^(-5/2) / h0^3, I_2^2 / (I_1 I_3) = 1 / (1 + eps^2/2), so
    smooth_drag = (1 + 2 eps^2) / (1 + eps^2/2), rough_viscous = (1 - eps^2) / (1 + eps^2/2),
    form_drag = 3 eps^2 / (1 + eps^2/2), couette = 1.

    Parameters
    ----------
    eps : float or array
        Relative amplitude, 0 <= eps < 1 [-].

    Returns
    -------
    WallStresses
        Dimensionless stresses [-].
    """
    eps = np.asarray(eps, dtype=float)
    den = 1 + eps**2 / 2
    return WallStresses(smooth_drag=(1 + 2 * eps**2) / den, rough_viscous=(1 - eps**2) / den,
                        form_drag=3 * eps**2 / den, couette=np.ones_like(eps))


# ------------------------------------------------------------------------- 2D periodic surface


@dataclass(frozen=True)
class PeriodicSurface:
    """Heights of a periodic rough wall on an n x n cell grid (cell i spans [i d, (i+1) d]).

    Attributes
    ----------
    centre : ndarray (n, n)
        Heights delta at the cell centres ((i + 1/2) d, (j + 1/2) d); axis 0 is x (sliding) [sigma].
    x_face : ndarray (n, n)
        Heights at the x-faces ((i + 1) d, (j + 1/2) d), between cell i and i + 1 [sigma].
    y_face : ndarray (n, n)
        Heights at the y-faces ((i + 1/2) d, (j + 1) d) [sigma].
    slope_x, slope_y : ndarray (n, n)
        d delta / dx and d delta / dy at the cell centres [sigma / lambda].
    cell : float
        Cell size d [lambda].
    """

    centre: np.ndarray
    x_face: np.ndarray
    y_face: np.ndarray
    slope_x: np.ndarray
    slope_y: np.ndarray
    cell: float


@dataclass(frozen=True)
class RoughWall:
    """A periodic rough wall as a finite Fourier series, to be sampled on any grid.

    delta(x, y) = sum over (j, l) of c[j, l] exp(i 2 pi (j x + l y) / length), with (j, l) the
    integer wavenumbers of ``numpy.fft.fftfreq(m) * m`` (m = c.shape[0], Nyquist row and column 0).

    Attributes
    ----------
    coefficients : ndarray (m, m), complex
        Fourier coefficients c [sigma], Hermitian (delta is real).
    length : float
        Side of the periodic square [lambda].
    """

    coefficients: np.ndarray
    length: float

    def on_grid(self, n):
        """Sample the wall on an n x n cell grid (n >= m): exact values of the Fourier series.

        Parameters
        ----------
        n : int
            Cells per side.

        Returns
        -------
        PeriodicSurface
        """
        m = self.coefficients.shape[0]
        if n < m:
            raise ValueError(f"grid of {n} cells is coarser than the wall's {m} Fourier modes")
        cell = self.length / n
        wave = np.fft.fftfreq(m) * m
        spectrum = np.zeros((n, n), dtype=complex)
        idx = np.mod(wave.astype(int), n)
        spectrum[np.ix_(idx, idx)] = self.coefficients * n * n
        k = 2 * np.pi * np.fft.fftfreq(n, d=cell)
        k[np.abs(k) * cell >= np.pi] = 0.0            # only the zero coefficients sit there
        kx, ky = k[:, None], k[None, :]

        def field(factor):
            return np.real(np.fft.ifft2(spectrum * factor))

        half = 0.5 * cell
        return PeriodicSurface(centre=field(np.exp(1j * (kx + ky) * half)),
                               x_face=field(np.exp(1j * (2 * kx + ky) * half)),
                               y_face=field(np.exp(1j * (kx + 2 * ky) * half)),
                               slope_x=field(1j * kx * np.exp(1j * (kx + ky) * half)),
                               slope_y=field(1j * ky * np.exp(1j * (kx + ky) * half)),
                               cell=cell)

    def rms(self):
        """RMS height of the wall (Parseval) [sigma]."""
        return float(np.sqrt(np.sum(np.abs(self.coefficients) ** 2)))


def wall_from_samples(heights, length):
    """The trigonometric interpolant of samples at the corner points (i d, j d), d = length / n.

    Parameters
    ----------
    heights : ndarray (m, m)
        Heights at the grid's corner points, axis 0 along x; m even [sigma].
    length : float
        Side of the periodic square [lambda].

    Returns
    -------
    RoughWall
        Its Nyquist row and column are dropped (no unique half-cell shift).
    """
    heights = np.asarray(heights, dtype=float)
    m = heights.shape[0]
    if heights.ndim != 2 or heights.shape[1] != m or m < 4 or m % 2:
        raise ValueError("heights must be a square array with an even number >= 4 of points a side")
    coefficients = np.fft.fft2(heights) / (m * m)
    coefficients[m // 2, :] = 0.0
    coefficients[:, m // 2] = 0.0
    return RoughWall(coefficients=coefficients, length=float(length))


def gaussian_wall(length, rng, correlation_length=1.0, modes_per_length=4.0):
    """Isotropic Gaussian random wall with a Gaussian autocorrelation, periodic, unit RMS.

    White noise in Fourier space filtered by the square root of the spectrum of
    R(r) = sigma^2 exp(-r^2 / lambda^2) (2D spectrum proportional to exp(-k^2 lambda^2 / 4)),
    zero mean, scaled to RMS 1 exactly. lambda is the 1/e correlation length (R = 1/2 at
    0.83 lambda, 0.1 at 1.52 lambda); the RMS slope per direction is sqrt(2) sigma / lambda.
    The series keeps ``modes_per_length`` modes per lambda along each axis (4: the highest has
    2e-9 of the amplitude of the lowest), so the same wall can be sampled on any finer grid.

    Parameters
    ----------
    length : float
        Side of the periodic square [unit of lengths, lambda = 1 by default].
    rng : numpy.random.Generator
        Source of the white noise.
    correlation_length : float
        lambda [same unit as length].
    modes_per_length : float
        Fourier modes per lambda along each axis.

    Returns
    -------
    RoughWall
        Heights in units of sigma.
    """
    m = 2 * int(np.ceil(modes_per_length * length / correlation_length / 2))
    k = 2 * np.pi * np.fft.fftfreq(m) * m / length
    k2 = k[:, None] ** 2 + k[None, :] ** 2
    coefficients = np.fft.fft2(rng.standard_normal((m, m))) * np.exp(-k2 * correlation_length**2 / 8)
    coefficients[0, 0] = 0.0
    coefficients[m // 2, :] = 0.0
    coefficients[:, m // 2] = 0.0
    wall = RoughWall(coefficients=coefficients, length=float(length))
    return RoughWall(coefficients=coefficients / wall.rms(), length=float(length))


# ------------------------------------------------------------------------------- 2D Reynolds


@dataclass(frozen=True)
class FlowResult:
    """Mean stresses of the film over a 2D periodic rough wall, in units of eta U / sigma.

    Attributes
    ----------
    smooth_drag : float
        Transmitted stress: the smooth wall's drag mean((4 - 6 ubar_x) / h) over the wetted cells,
        ubar = q / h the depth-averaged velocity [U] (wall shear of the Couette-Poiseuille profile
        eta (4 U - 6 ubar) / h). ubar stays bounded at contact lines, where the pressure and
        (h/2) dp/dx grow like 1/h, so this converges on grids that do not resolve the cut-off gap.
    rough_viscous : float
        Viscous shear on the rough wall, mean((6 ubar_x - 2) / h) over the wetted cells.
    form_drag : float
        Pressure force on the rough wall in x, evaluated from the pressure and the wall's own
        slope: mean(p d(delta)/dx) over the wetted cells plus the force on the step of height
        ``cutoff`` where the wetted region ends (p h_c n_x on its boundary faces). Independent of
        the shear terms: rough_viscous + form_drag -> smooth_drag once the grid resolves the
        pressure near contact lines (cell << cutoff / |grad delta|; everywhere if no contact).
    smooth_drag_faces : float
        Second evaluation of the transmitted stress: couette + mean((h/2) dp/dx) with dp/dx on the
        open x-faces. Converges to smooth_drag only once the grid resolves the contact lines.
    couette : float
        mean(1/h) over the wetted cells (h > cutoff), 0 elsewhere.
    poiseuille : float
        mean((h/2) dp/dx) over the open x-faces.
    dissipation : float
        mean(h^3 |grad p|^2 / 12) over the open faces: equals poiseuille when the linear system is
        solved (energy balance of the pressure flow).
    contact_fraction : float
        Fraction of cells with h <= cutoff (no oil) [-].
    """

    smooth_drag: float
    rough_viscous: float
    form_drag: float
    smooth_drag_faces: float
    couette: float
    poiseuille: float
    dissipation: float
    contact_fraction: float


def solve_film(surface, H, cutoff=SHEAR_CUTOFF_GAP):
    """Steady Reynolds flow between a smooth wall sliding in x and a fixed rough wall, periodic.

    Finite volumes on the cell grid of ``surface``: gap h = H - delta; cells with h <= cutoff carry
    neither oil flow nor shear (asperity contact; Cui's eps* cut-off ends the Couette shear of
    phi_f at the same gap); a face is open when its own gap and both its cells' gaps exceed the
    cut-off (the Patir-Cheng flow simulations' zero flux through contacts). The flux through an open
    x-face is q_x = h_f/2 - h_f^3 (p_E - p_P) / (12 d) (units U sigma), through a y-face
    q_y = -h_f^3 (p_N - p_P) / (12 d); their balance per cell, sum g_f (p_P - p_nb) = -d (h_e - h_w)/2
    with g_f = h_f^3 / 12, is div(h^3 grad p / 12) = dh/dx / 2, solved sparse (SuperLU). The
    pressure level of each connected wetted region (the percolating film, a trapped pocket) is set
    to a zero mean; it does not enter the stresses. The depth-averaged velocity of a cell, ubar_x,
    is the mean of q_x / h_f over its open x-faces (0 if none).

    Parameters
    ----------
    surface : PeriodicSurface
        Rough wall heights [sigma] on a grid of cell size [lambda].
    H : float
        Nominal gap over the rough wall's mean plane, h0 / sigma [-].
    cutoff : float
        Local gap at and below which the film carries no flow and no shear [sigma]; default
        3 eps* = 0.01 (Cui 2019 after Eq. 6). With contact lines the shear grows like ln(1/cutoff).

    Returns
    -------
    FlowResult
        Mean stresses [eta U / sigma].
    """
    if not cutoff >= 0:
        raise ValueError(f"cutoff must be >= 0, got {cutoff}")
    d = surface.cell
    n = surface.centre.shape[0]
    h = H - surface.centre
    wet = h > cutoff
    wet_east, wet_north = np.roll(wet, -1, axis=0), np.roll(wet, -1, axis=1)
    open_x = (H - surface.x_face > cutoff) & wet & wet_east
    open_y = (H - surface.y_face > cutoff) & wet & wet_north
    hx = np.where(open_x, H - surface.x_face, 0.0)
    hy = np.where(open_y, H - surface.y_face, 0.0)
    gx, gy = hx**3 / 12.0, hy**3 / 12.0
    rhs = -d * (hx - np.roll(hx, 1, axis=0)) / 2.0                 # minus the Couette outflow

    index = np.arange(n * n).reshape(n, n)
    east, north = np.roll(index, -1, axis=0), np.roll(index, -1, axis=1)
    rows = np.concatenate([index[open_x], index[open_y]])
    cols = np.concatenate([east[open_x], north[open_y]])
    weights = np.concatenate([gx[open_x], gy[open_y]])
    coupling = sparse.coo_matrix((weights, (rows, cols)), shape=(n * n, n * n)).tocsr()
    coupling = coupling + coupling.T
    laplacian = sparse.diags(np.asarray(coupling.sum(axis=1)).ravel()) - coupling

    cells = index[wet]
    p = np.zeros(n * n)
    if cells.size:
        _, region = csgraph.connected_components(coupling[cells][:, cells], directed=False)
        pinned = np.zeros(cells.size, dtype=bool)
        pinned[np.unique(region, return_index=True)[1]] = True    # one cell per region: p = 0
        free = cells[~pinned]
        if free.size:
            p[free] = spsolve(laplacian[free][:, free].tocsc(), rhs.ravel()[free])
        p_cells = p[cells]
        p[cells] = p_cells - (np.bincount(region, p_cells) / np.bincount(region))[region]
    p = p.reshape(n, n)

    dpx = (np.roll(p, -1, axis=0) - p) / d
    dpy = (np.roll(p, -1, axis=1) - p) / d
    qx = hx / 2.0 - gx * dpx                                       # east-face flux [U sigma]
    # depth-averaged velocity: q / h on the open x-faces, averaged over a cell's open faces (q / h
    # at the centre would divide a face's flux by a centre gap that can be far thinner)
    u_face = np.where(open_x, qx / np.where(open_x, hx, 1.0), 0.0)
    n_open = open_x.astype(float) + np.roll(open_x, 1, axis=0)
    ubar = (u_face + np.roll(u_face, 1, axis=0)) / np.maximum(n_open, 1.0)
    inv_h = np.where(wet, 1.0 / np.where(wet, h, 1.0), 0.0)
    couette = np.mean(inv_h)
    poiseuille = np.mean(hx / 2.0 * dpx)
    flanks = np.mean(np.where(wet, p * surface.slope_x, 0.0))
    # a wetted cell whose east (west) neighbour is dry: the dry region's step of height cutoff
    # faces -x (+x), and the pressure on it pushes the rough wall in +x (-x)
    step = cutoff * np.mean(p * ((wet & ~wet_east).astype(float)
                                 - (wet & ~np.roll(wet, 1, axis=0)).astype(float))) / d
    return FlowResult(smooth_drag=np.mean((4.0 - 6.0 * ubar) * inv_h),
                      rough_viscous=np.mean((6.0 * ubar - 2.0) * inv_h),
                      form_drag=flanks + step,
                      smooth_drag_faces=couette + poiseuille,
                      couette=couette, poiseuille=poiseuille,
                      dissipation=np.mean(gx * dpx**2 + gy * dpy**2),
                      contact_fraction=float(np.mean(~wet)))


# ---------------------------------------------------------------------- transmitted shear factor


@dataclass(frozen=True)
class EnsembleResult:
    """Ensemble means of the film over Gaussian rough walls, as factors of eta U / h_T.

    Each factor is a mean stress times h_T / (eta U), h_T = h Phi(H) + sigma phi(H) the average gap
    (Bao 2020 Eq. 10, ``roughness.average_gap``), so it replaces (phi_f -+ phi_fs) in Cui 2019
    Eq. 9 (``shear.viscous_torque``) directly. Arrays are indexed like ``H``.

    Attributes
    ----------
    H : ndarray
        Film ratios h / sigma [-].
    transmitted : ndarray
        phi_T: the transmitted stress (the smooth wall's drag) [-].
    transmitted_stderr : ndarray
        Standard error of ``transmitted`` over the walls [-].
    couette : ndarray
        The Couette part, h_T mean(1 / h) over the wetted area [-].
    form_drag : ndarray
        h_T mean(h dp/dx) from the depth-averaged velocity, (smooth_drag - rough_viscous) h_T [-];
        the transmitted factor is couette + form_drag / 2.
    form_drag_direct : ndarray
        The pressure on the rough wall's flanks and contact steps times h_T [-] (converges to
        ``form_drag`` once the grid resolves the contact lines).
    contact_fraction : ndarray
        Mean fraction of the area with h <= cutoff [-].
    """

    H: np.ndarray
    transmitted: np.ndarray
    transmitted_stderr: np.ndarray
    couette: np.ndarray
    form_drag: np.ndarray
    form_drag_direct: np.ndarray
    contact_fraction: np.ndarray


def transmitted_shear_ensemble(H, n_walls, *, length=8.0, cells_per_length=32, cutoff=SHEAR_CUTOFF_GAP,
                               seed=0):
    """Transmitted shear factor phi_T(H) of a smooth wall sliding over Gaussian rough walls.

    Each of ``n_walls`` walls (``gaussian_wall``, seeds seed, seed + 1, ...) is solved together with
    its transpose (the same wall turned by 90 degrees), whose mean makes each pair isotropic to
    second order in sigma / h; the pair means are the samples of the ensemble. The same walls serve
    every H (common random numbers: the curves are smooth in H).

    Parameters
    ----------
    H : array_like
        Film ratios h / sigma [-].
    n_walls : int
        Number of walls (>= 2).
    length : float
        Side of each periodic wall [lambda].
    cells_per_length : int
        Grid cells per lambda (32: transmitted stress within 2 % per wall of 64 cells, ensemble
        mean within 0.8 %; without contact 16 cells converge to 1e-4).
    cutoff : float
        Gap at and below which the film carries no flow and no shear [sigma] (Cui's 3 eps*).
    seed : int
        Seed of the first wall.

    Returns
    -------
    EnsembleResult
    """
    H = np.atleast_1d(np.asarray(H, dtype=float))
    if n_walls < 2:
        raise ValueError(f"n_walls must be >= 2 for a standard error, got {n_walls}")
    n = int(round(cells_per_length * length))
    fields = ("smooth_drag", "rough_viscous", "form_drag", "couette", "contact_fraction")
    samples = np.zeros((n_walls, H.size, len(fields)))
    for i in range(n_walls):
        wall = gaussian_wall(length, np.random.default_rng(seed + i))
        turned = RoughWall(coefficients=wall.coefficients.T, length=wall.length)
        for surface in (wall.on_grid(n), turned.on_grid(n)):
            for j, h in enumerate(H):
                r = solve_film(surface, h, cutoff=cutoff)
                samples[i, j] += [getattr(r, f) / 2 for f in fields]
    gap = average_gap(H, 1.0)
    mean = samples.mean(axis=0)
    stderr = samples[:, :, 0].std(axis=0, ddof=1) / np.sqrt(n_walls)
    return EnsembleResult(H=H, transmitted=mean[:, 0] * gap, transmitted_stderr=stderr * gap,
                          couette=mean[:, 3] * gap, form_drag=(mean[:, 0] - mean[:, 1]) * gap,
                          form_drag_direct=mean[:, 2] * gap, contact_fraction=mean[:, 4])
