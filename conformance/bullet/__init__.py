"""pyBullet's truth: clients, poses and shapes as pyBullet reports them, where a body's drawing should be
(``truth``), the kit's events on a simulation, the physics laws and collision filters the checks hold
pyBullet to, its known deviations, and a frame's physics state. Imports nothing of the kit but ``errors``
(internal: the kit's checks and commands use it; users do not)."""
