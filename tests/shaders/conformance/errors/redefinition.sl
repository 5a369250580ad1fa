/* must stay an error: one name declared twice in one scope */
displacement redefinition()
{
    float s = 1;
    float s = 2;
}
