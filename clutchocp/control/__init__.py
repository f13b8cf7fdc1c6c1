"""What the speed control of the HVD (:mod:`clutchocp.hvd`) and the slip control of a shift
(:mod:`clutchocp.shiftcontrol`) share: spec files, exact linearisation of a DAE, LQR design.

* :mod:`~clutchocp.control.spec` -- reading a spec of controllers/ and checking its tables;
* :mod:`~clutchocp.control.linearize` -- exact CasADi Jacobians, algebraic variables eliminated;
* :mod:`~clutchocp.control.lqr` -- stationary and finite-horizon time-varying discrete LQR.
"""
