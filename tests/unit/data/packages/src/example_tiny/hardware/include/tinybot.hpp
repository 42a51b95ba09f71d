// the drivers would be here
