"""Drake systems of the package: the interceptor's blocks (paper Fig. 1), the fused fast path,
the baseline controllers and the perception blocks, each a LeafSystem (or a small diagram)."""
