/* must stay an error: an untyped triple where nothing gives it a type */
displacement untyped()
{
    float d = (1, 0, 0) . (0, 1, 0);
}
