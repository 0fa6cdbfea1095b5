"""Dense stereo matching (issue 28): the census transform first; the matching and aggregation blocks follow."""
