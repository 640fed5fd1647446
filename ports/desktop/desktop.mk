# ports/desktop build fragment (filled in by its owner)
