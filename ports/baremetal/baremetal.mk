# ports/baremetal build fragment (filled in by its owner)
