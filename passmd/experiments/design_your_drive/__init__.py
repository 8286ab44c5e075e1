"""The chapter "Design your own drive" (beyond the paper): Sections 2–5 applied to a drive of your own."""
