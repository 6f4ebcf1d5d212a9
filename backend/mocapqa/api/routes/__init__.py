"""One router module per resource: health, takes, runs, reviews, filters, stream."""
