"""Phased direct collocation: one NLP for a sequence of phases, each on its own mesh and duration.

An engagement passes through the modes of :class:`~clutchocp.engagement.model.EngagementModel`:
fill (``approach_*``: piston stroking against its return spring, plates at rest) -> impact (Bao
Eq. 22 reset) -> slip (``pressing_*``) -> lock-up. Each phase is a
:class:`~clutchocp.optimal.collocation.StagedProblem` transcribed by its own
:class:`~clutchocp.optimal.collocation.DirectCollocation` (own free duration T_k, own mesh); the
phases are joined by link rows

    x_start(k + 1) = reset_k(x_end(k)),      u_start(k + 1) = u_end(k),

the second only for a piecewise-linear (continuous) command: a piecewise-constant command may change
at a junction as at any interval boundary. With more than one phase one row carries the total time
sum_k T_k (its upper bound is the engagement-time limit). A single phase has no link and no total-time row: its NLP vector and rows
are those of its own transcription, so today's slip-phase problem is the one-phase case.

Exact derivatives: each phase's Jacobian and Hessian come from
:func:`~clutchocp.optimal.derivatives.structured_derivatives` (block diagonal); the few link rows
are differentiated by CasADi.
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np

from .collocation import DirectCollocation, StagedProblem
from .derivatives import structured_derivatives


@dataclass
class Phase:
    """One phase of an engagement problem.

    Parameters
    ----------
    name : str
        ``"fill"`` (piston stroke to the kiss point) or ``"slip"`` (pack pressed, up to lock-up).
    mode : str
        The model mode the phase follows.
    problem : StagedProblem
        Its scaled problem (``x0`` None for a phase that starts where the previous one ended).
    transcription : DirectCollocation
        Its mesh.
    """

    name: str
    mode: str
    problem: StagedProblem
    transcription: DirectCollocation


class PhasedNLP:
    """The NLP of a sequence of phases.

    Parameters
    ----------
    phases : list of Phase
    links : list of casadi.Function
        One per junction: ``(x_end[n_x], x_start[n_x]) -> residual`` (zero when the start of the next
        phase is the reset image of the end of this one). The command continuity rows (linear
        control) are added here.

    Attributes
    ----------
    parts : list of TranscribedNLP
        The transcription of each phase; ``offsets[k]`` is where its variables start in w and
        ``row_offsets[k]`` where its rows start in g.
    rows : dict
        ``"links"`` and ``"total_time"`` (empty for one phase) slices of g.
    """

    def __init__(self, phases, links=()):
        if len(links) != len(phases) - 1:
            raise ValueError("one link per junction of two phases is needed")
        self.phases = list(phases)
        self.links = list(links)
        self.parts = [ph.transcription.transcribe(ph.problem) for ph in self.phases]
        sizes = [part.lbx.size for part in self.parts]
        self.offsets = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(int)
        n_p = self.phases[0].problem.n_p
        W = ca.MX.sym("w", int(sum(sizes)))
        P = ca.MX.sym("p", n_p)
        self._W, self._P = W, P
        f, g, self.row_offsets, row = 0, [], [], 0
        for k, part in enumerate(self.parts):
            fn = ca.Function(f"phase_{k}", [part.nlp["x"], part.nlp["p"]], [part.nlp["f"], part.nlp["g"]])
            fk, gk = fn(self.w_of(W, k), P)
            f += fk
            g.append(gk)
            self.row_offsets.append(row)
            row += part.lbg.size
        link_rows = self._link_rows(W)
        total = self._total_time(W) if len(self.parts) > 1 else ca.MX(0, 1)
        self.g_link = ca.vertcat(link_rows, total)
        self.rows = {"links": slice(row, row + link_rows.numel()),
                     "total_time": slice(row + link_rows.numel(), row + link_rows.numel() + total.numel())}
        self.nlp = {"x": W, "f": f, "g": ca.vertcat(*g, self.g_link), "p": P}
        self.lbx = np.concatenate([part.lbx for part in self.parts])
        self.ubx = np.concatenate([part.ubx for part in self.parts])
        self.lbg = np.concatenate([part.lbg for part in self.parts] + [np.zeros(link_rows.numel()),
                                                                         np.full(total.numel(), -np.inf)])
        self.ubg = np.concatenate([part.ubg for part in self.parts] + [np.zeros(link_rows.numel()),
                                                                         np.full(total.numel(), np.inf)])

    # -- layout -----------------------------------------------------------------------------------
    def w_of(self, w, k):
        """The variables of phase k in a full vector (numpy or CasADi)."""
        return w[int(self.offsets[k]):int(self.offsets[k]) + self.parts[k].lbx.size]

    def t_slice(self, k):
        """Slice of w holding phase k's duration copies (scaled)."""
        s = self.parts[k].t_slice
        return slice(int(self.offsets[k]) + s.start, int(self.offsets[k]) + s.stop)

    def end_rows(self, k):
        """Rows of phase k's end constraints in g."""
        s = self.parts[k].end_rows
        return slice(self.row_offsets[k] + s.start, self.row_offsets[k] + s.stop)

    def unpack(self, w):
        """Per phase: ``{"x", "xc", "u", "T"}`` as :meth:`TranscribedNLP.unpack`."""
        w = np.asarray(w, dtype=float).ravel()
        return [part.unpack(self.w_of(w, k)) for k, part in enumerate(self.parts)]

    def _ends(self, W, k):
        """(x_end, u_end, x_start, u_start, T) of phase k as slices of W."""
        part, off = self.parts[k], int(self.offsets[k])
        n_x, n_u = part.problem.n_x, part.problem.n_u
        (xs, _), (us, (n_ctrl, _)) = part.layout["x"], part.layout["u"]
        N = part.transcription.intervals
        x_end = W[off + xs + N * n_x:off + xs + (N + 1) * n_x]
        u_end = W[off + us + (n_ctrl - 1) * n_u:off + us + n_ctrl * n_u]
        return x_end, u_end, W[off + xs:off + xs + n_x], W[off + us:off + us + n_u], W[off + part.t_slice.stop - 1]

    def _link_rows(self, W):
        rows = []
        for k, link in enumerate(self.links):
            x_end, u_end, _, _, _ = self._ends(W, k)
            _, _, x_start, u_start, _ = self._ends(W, k + 1)
            rows.append(link(x_end, x_start))
            if self.parts[k].transcription.control == "linear":
                rows.append(u_start - u_end)
        return ca.vertcat(*rows) if rows else ca.MX(0, 1)

    def _total_time(self, W):
        return sum(self._ends(W, k)[4] for k in range(len(self.parts)))

    def total_time(self, w):
        """Sum of the phase durations (scaled) of a numeric vector."""
        return sum(float(np.asarray(w)[self.t_slice(k)][-1]) for k in range(len(self.parts)))


def phased_derivatives(pnlp):
    """``jac_g`` and ``hess_lag`` for ``casadi.nlpsol`` of a :class:`PhasedNLP`.

    Each phase's blocks come from :func:`structured_derivatives` (no coupling between phases but
    the link rows, whose few entries CasADi differentiates).
    """
    W, P = pnlp._W, pnlp._P
    n_g = pnlp.lbg.size
    blocks = [structured_derivatives(part) for part in pnlp.parts]
    jac_parts, g_parts = [], []
    for k, d in enumerate(blocks):
        gk, jk = d["jac_g"](pnlp.w_of(W, k), P)
        g_parts.append(gk)
        jac_parts.append(jk)
    jac_link = ca.jacobian(pnlp.g_link, W)
    jac = ca.vertcat(ca.diagcat(*jac_parts), jac_link)
    jac_g = ca.Function("phased_jac_g", [W, P], [ca.vertcat(*g_parts, pnlp.g_link), jac], ["x", "p"],
                        ["g", "jac_g_x"])
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", n_g)
    hess_parts = []
    for k, (d, part) in enumerate(zip(blocks, pnlp.parts)):
        rows = slice(pnlp.row_offsets[k], pnlp.row_offsets[k] + part.lbg.size)
        hess_parts.append(d["hess_lag"](pnlp.w_of(W, k), P, lam_f, lam_g[rows]))
    hess = ca.diagcat(*hess_parts)
    n_link = pnlp.g_link.numel()
    if n_link:
        link_lagrangian = ca.dot(lam_g[n_g - n_link:], pnlp.g_link)
        hess_link = ca.triu(ca.hessian(link_lagrangian, W)[0])
        if hess_link.nnz():
            hess = hess + hess_link
    hess_lag = ca.Function("phased_hess_l", [W, P, lam_f, lam_g], [hess], ["x", "p", "lam_f", "lam_g"],
                           ["triu_hess_gamma_x_x"])
    return {"jac_g": jac_g, "hess_lag": hess_lag}
