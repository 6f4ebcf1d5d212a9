"""One router module per resource: health, takes, runs, reviews, filters, stream; the
vendored Plotly bundle's route (``plotly_bundle``)."""
