"""Models of motion: the hand-derived Kane-Tseng equations (compiled kernel, its Python face,
integration with chart switching), their normal modes, and the 1-DOF Lagrange torsion models."""
