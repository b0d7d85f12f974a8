"""Parallel volume rendering: the taxonomy of partitions, their communication (an analytic
model and a simulated mesh/torus network), and a real MPI renderer."""
