"""What the bench scripts' figures share: two panels side by side, drawn
without a display (matplotlib's Agg backend, from Debian's python3-matplotlib)."""


def two_panels():
    """(figure, (left axes, right axes)), 10 x 4 inches."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots(1, 2, figsize=(10, 4))
