# tools build fragment (filled in by its owner)
