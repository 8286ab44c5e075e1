"""The chapter "Design your own drive": the worked example and design maps."""
