"""The lumped and transfer-function fits' default settings (`lumped_fit`), in a module of their own so that the
command line states them in its help without importing the fit (scipy)."""

#: the multi-start of the lumped fit: this many log-uniform starts inside `lumped_fit.START_BOX`, each at most
#: `START_NFEV` evaluations on at most about `START_POINTS` of the frequencies, the best `POLISHED` polished on all of
#: them (at most `POLISH_NFEV` evaluations each)
STARTS, START_NFEV, START_POINTS, POLISHED, POLISH_NFEV = 32, 100, 80, 3, 2000
#: the default band (Hz), its spacing (Hz), the transfer function's default order (denominator degree)
BAND, DF, DEFAULT_ORDER = (0.0, 20.0), 0.05, 7
